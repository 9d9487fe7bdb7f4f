#include "rundir/rows.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
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

namespace {

// Checks that `table` has no columns after `expected` (which it starts with).
void CheckNoMoreColumns(const CsvTable& table, const std::vector<std::string>& expected) {
  if (table.columns.size() == expected.size()) return;
  throw std::runtime_error(table.path + ": column " + table.columns[expected.size()] +
                           ": expected no column after " + expected.back() + " (got " +
                           std::to_string(table.columns.size()) + " columns, expected " +
                           std::to_string(expected.size()) + ")");
}

// The value of column `c` of row `r` as a whole number in [0, hi].
int WholeNumber(const CsvTable& table, std::size_t r, int c, double hi) {
  const double value = table.rows[r][c];
  if (!(value >= 0.0 && value <= hi && std::floor(value) == value)) {
    throw std::runtime_error(table.path + ":" + std::to_string(table.lines[r]) + ": column " +
                             table.columns[c] + ": expected a whole number in [0, " +
                             FormatDouble(hi) + "] (got " + FormatDouble(value) + ")");
  }
  return static_cast<int>(value);
}

// The pose in columns c, c + 1, c + 2 of `row`.
Pose2 PoseAt(const std::vector<double>& row, int c) { return Pose2(row[c], row[c + 1], row[c + 2]); }

}  // namespace

std::vector<TrajectoryRow> ReadTrajectoryRows(const std::string& path) {
  const CsvTable table = ReadTrajectoryCsv(path);
  // The columns after the recorded ones, by name: each known, none twice.
  const std::size_t num_recorded = RecordedTrajectoryColumns().size();
  std::vector<std::string> known = {"explored"};
  const std::vector<std::string> names = TrajectoryFilterNames(table.columns);
  for (const std::string& name : names) {
    for (const std::string& column : FilterColumns(name)) known.push_back(column);
  }
  std::map<std::string, int> index;
  for (std::size_t c = num_recorded; c < table.columns.size(); ++c) {
    const std::string& column = table.columns[c];
    if (std::find(known.begin(), known.end(), column) == known.end()) {
      throw std::runtime_error(path + ": column " + column + ": not a column of " +
                               std::string(kTrajectoryFile) + " (docs/run_directory.md)");
    }
    if (!index.emplace(column, static_cast<int>(c)).second) {
      throw std::runtime_error(path + ": column " + column + ": twice");
    }
  }
  const bool has_filters = index.size() > index.count("explored");
  // Column `column`: its index; -1 when it is absent and `optional`.
  auto column_of = [&](const std::string& column, bool optional) {
    const auto it = index.find(column);
    if (it != index.end()) return it->second;
    if (optional) return -1;
    throw std::runtime_error(path + ": no column " + column + " (the filters' columns are " +
                             "all there or none; only explored, *_period, *_open_loop, *_nees " +
                             "and *_processed may be missing, as in older runs)");
  };
  const int explored = column_of("explored", true);
  // Each filter's column of each of FilterColumnSuffixes(), by suffix.
  const std::vector<std::string>& suffixes = FilterColumnSuffixes();
  const std::vector<std::string> optional = {"period", "open_loop", "nees", "processed"};
  std::vector<std::map<std::string, int>> filters;
  if (has_filters) {
    for (const std::string& name : names) {
      filters.emplace_back();
      for (const std::string& suffix : suffixes) {
        const bool may_miss = std::find(optional.begin(), optional.end(), suffix) != optional.end();
        filters.back()[suffix] = column_of(name + "_" + suffix, may_miss);
      }
    }
  }
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

  std::vector<TrajectoryRow> rows(table.rows.size());
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    const std::vector<double>& v = table.rows[r];
    TrajectoryRow& row = rows[r];
    // The recorded columns, in their order (checked by ReadTrajectoryCsv).
    row.t_s = v[0];
    row.X_WR_true = PoseAt(v, 1);
    row.X_WR_odometry = PoseAt(v, 4);
    row.command = {v[7], v[8]};
    row.explored = explored >= 0 ? v[explored] : kNaN;
    for (const std::map<std::string, int>& columns : filters) {
      // The value of column `suffix`; NaN when it is absent.
      auto value = [&](const char* suffix) {
        const int c = columns.at(suffix);
        return c >= 0 ? v[c] : kNaN;
      };
      auto count = [&](const char* suffix) { return WholeNumber(table, r, columns.at(suffix), 1e9); };
      FilterRow filter;
      filter.name = names[row.filters.size()];
      filter.X_WR = Pose2(value("x"), value("y"), value("th"));
      filter.P << value("pxx"), value("pxy"), value("pxth"), value("pxy"), value("pyy"),
          value("pyth"), value("pxth"), value("pyth"), value("pthth");
      filter.num_features = count("nfeat");
      filter.num_matched = count("nmatched");
      filter.num_updated = count("nupdated");
      filter.processing_us = value("us");
      filter.period_s = value("period");
      filter.open_loop_s = value("open_loop");
      filter.nees = value("nees");
      const int processed = columns.at("processed");
      filter.processed = processed < 0 || WholeNumber(table, r, processed, 1.0) == 1;
      row.filters.push_back(filter);
    }
  }
  return rows;
}

std::vector<ScanRow> ReadScanRows(const std::string& path) {
  const CsvTable table = ReadScansCsv(path);
  std::vector<ScanRow> rows(table.rows.size());
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    const std::vector<double>& v = table.rows[r];
    rows[r].t_s = v[0];
    rows[r].X_WS = PoseAt(v, 1);
    rows[r].ranges_m.assign(v.begin() + kScanRangesStart, v.end());
  }
  return rows;
}

std::vector<ReferenceRow> ReadReferenceRows(const std::string& path) {
  const CsvTable table = ReadCsv(path);
  const std::vector<std::string> expected = ReferenceColumns();
  CheckLeadingColumns(table, expected);
  CheckNoMoreColumns(table, expected);
  CheckIncreasingTimes(table, 0);
  std::vector<ReferenceRow> rows(table.rows.size());
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    rows[r].t_s = table.rows[r][0];
    rows[r].X_WR = PoseAt(table.rows[r], 1);
  }
  return rows;
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
