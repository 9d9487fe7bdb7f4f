#include "rundir/rows.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "rundir/csv_reader.h"
#include "rundir/layout.h"

namespace mjslam::rundir {

void AddTrajectoryRow(const TrajectoryRow& row, CsvWriter* trajectory) {
  trajectory->Add(row.t_s);
  for (const double v : {row.X_WR_true.x, row.X_WR_true.y, row.X_WR_true.theta,
                         row.X_WR_odometry.x, row.X_WR_odometry.y, row.X_WR_odometry.theta,
                         row.command.v_mps, row.command.w_radps}) {
    trajectory->Add(v);
  }
  if (std::isfinite(row.explored)) {
    trajectory->Add(row.explored);
  } else {
    trajectory->AddEmpty();
  }
  for (const FilterRow& f : row.filters) {
    trajectory->Add(f.X_WR.x);
    trajectory->Add(f.X_WR.y);
    trajectory->Add(f.X_WR.theta);
    trajectory->Add(f.P(0, 0));
    trajectory->Add(f.P(0, 1));
    trajectory->Add(f.P(0, 2));
    trajectory->Add(f.P(1, 1));
    trajectory->Add(f.P(1, 2));
    trajectory->Add(f.P(2, 2));
    trajectory->Add(f.num_features);
    trajectory->Add(f.num_matched);
    trajectory->Add(f.num_updated);
    trajectory->Add(f.processing_us);
    trajectory->Add(f.period_s);
    trajectory->Add(f.open_loop_s);
    // Empty where P is (nearly) singular: the known start and the steps after.
    if (std::isfinite(f.nees)) {
      trajectory->Add(f.nees);
    } else {
      trajectory->AddEmpty();
    }
    trajectory->Add(f.processed ? 1 : 0);
  }
  trajectory->EndRow();
}

void AddScanRow(double t_s, const Pose2& X_WS, const std::vector<double>& ranges_m,
                CsvWriter* scans) {
  scans->Add(t_s);
  scans->Add(X_WS.x);
  scans->Add(X_WS.y);
  scans->Add(X_WS.theta);
  for (const double r : ranges_m) scans->Add(r);
  scans->EndRow();
}

void AddExplorerRows(const ExplorerSnapshot& snapshot, CsvWriter* explorer) {
  auto add = [&](const char* kind, int index, const Eigen::Vector2d& p) {
    explorer->Add(snapshot.t_s);
    explorer->Add(std::string_view(kind));
    explorer->Add(index);
    explorer->Add(p.x());
    explorer->Add(p.y());
    explorer->EndRow();
  };
  const std::vector<Eigen::Vector2d>& frontiers = snapshot.frontier;
  for (std::size_t i = 0; i < frontiers.size(); ++i) add("frontier", static_cast<int>(i), frontiers[i]);
  if (snapshot.goal) add("goal", 0, *snapshot.goal);
  for (std::size_t i = 0; i < snapshot.path.size(); ++i) {
    add("path", static_cast<int>(i), snapshot.path[i]);
  }
}

namespace {

// The true pose (columns 1-3): finite and in range everywhere, or NaN
// everywhere in a recording that has no truth (a real log written by
// mjslam import).
void CheckTruePoseColumns(const CsvTable& table) {
  if (table.rows.empty() || !std::isnan(table.rows[0][1])) {
    CheckValuesInRange(table, 1, 3, -kMaxRecordedCoordinateM, kMaxRecordedCoordinateM);
    return;
  }
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    for (int c = 1; c <= 3; ++c) {
      if (std::isnan(table.rows[r][c])) continue;
      throw std::runtime_error(table.path + ":" + std::to_string(table.lines[r]) + ": column " +
                               table.columns[c] + ": expected nan, as in the first row (a " +
                               "recording without truth) (got " +
                               FormatDouble(table.rows[r][c]) + ")");
    }
  }
}

}  // namespace

CsvTable ReadTrajectoryCsv(const std::string& path) {
  CsvTable table = ReadCsv(path);
  if (table.rows.empty()) throw std::runtime_error(path + ": no rows");
  const std::vector<std::string> expected = RecordedTrajectoryColumns();
  CheckLeadingColumns(table, expected);
  CheckIncreasingTimes(table, 0);
  CheckTruePoseColumns(table);
  const int count = static_cast<int>(expected.size()) - 4;
  CheckValuesInRange(table, 4, count, -kMaxRecordedCoordinateM, kMaxRecordedCoordinateM);
  return table;
}

CsvTable ReadScansCsv(const std::string& path) {
  CsvTable table = ReadCsv(path);
  CheckLeadingColumns(table, {"t", "x", "y", "th"});
  CheckIncreasingTimes(table, 0);
  CheckTruePoseColumns(table);
  const int num_ranges = static_cast<int>(table.columns.size()) - kScanRangesStart;
  CheckValuesInRange(table, kScanRangesStart, num_ranges, 0.0, kMaxRecordedCoordinateM);
  return table;
}

std::vector<ExplorerSnapshot> ReadExplorerCsv(const std::string& path) {
  std::vector<ExplorerSnapshot> snapshots;
  if (!std::filesystem::exists(path)) return snapshots;
  const CsvTable table = ReadCsv(path, {"kind"});
  const int t = table.ColumnIndex("t");
  table.ColumnIndex("kind");  // the only text column: text[r][0]
  const int index = table.ColumnIndex("index"), x = table.ColumnIndex("x"), y = table.ColumnIndex("y");
  std::vector<std::pair<double, Eigen::Vector2d>> path_points;
  auto close = [&]() {
    if (snapshots.empty()) return;
    std::stable_sort(path_points.begin(), path_points.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [i, p] : path_points) snapshots.back().path.push_back(p);
    path_points.clear();
  };
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    const std::vector<double>& row = table.rows[r];
    if (snapshots.empty() || row[t] != snapshots.back().t_s) {
      close();
      snapshots.emplace_back();
      snapshots.back().t_s = row[t];
    }
    const std::string& k = table.text[r][0];
    const Eigen::Vector2d p(row[x], row[y]);
    if (k == "frontier") {
      snapshots.back().frontier.push_back(p);
    } else if (k == "goal") {
      snapshots.back().goal = p;
    } else if (k == "path") {
      path_points.emplace_back(row[index], p);
    } else {
      throw std::runtime_error(path + ":" + std::to_string(r + 2) +
                               ": kind: expected frontier, goal or path (got '" + k + "')");
    }
  }
  close();
  return snapshots;
}

}  // namespace mjslam::rundir
