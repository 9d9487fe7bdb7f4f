// The row writers and readers of rundir/rows.h and rundir/recording.h:
// trajectory rows in the documented columns and read back field by field,
// scan and reference rows read back, bad fields refused naming file, line
// and column, explorer snapshots written and read back, a recording read for
// a replay.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include "rundir/csv_reader.h"
#include "rundir/layout.h"
#include "rundir/recording.h"
#include "rundir/rows.h"

namespace mjslam::rundir {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "mjslam_rows_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(RowsTest, TrajectoryRowFillsTheColumnsAndLeavesUndefinedValuesEmpty) {
  const std::string path = rundir::PathIn(FreshDir("trajectory"), rundir::kTrajectoryFile);
  {
    CsvWriter writer(path, TrajectoryColumns());
    TrajectoryRow row;
    row.t_s = 0.5;
    row.X_WR_true = Pose2(1.0, 2.0, 0.25);
    row.X_WR_odometry = Pose2(1.5, 2.5, -0.5);
    row.command = {0.3, -0.1};
    row.explored = kNaN;
    for (int f = 0; f < 2; ++f) {
      FilterRow filter;
      filter.X_WR = Pose2(f, 0.0, 0.0);
      filter.P(0, 1) = 7.0;
      filter.P(1, 2) = 8.0;
      filter.num_features = 4 + f;
      filter.nees = f == 0 ? kNaN : 2.5;
      row.filters.push_back(filter);
    }
    AddTrajectoryRow(row, &writer);  // checks the number of fields itself
  }
  const CsvTable table = ReadCsv(path);
  ASSERT_EQ(table.rows.size(), 1u);
  const std::vector<double>& r = table.rows[0];
  EXPECT_EQ(r[table.ColumnIndex("odom_th")], -0.5);
  EXPECT_EQ(r[table.ColumnIndex("cmd_w")], -0.1);
  EXPECT_TRUE(std::isnan(r[table.ColumnIndex("explored")]));
  EXPECT_EQ(r[table.ColumnIndex("selective_x")], 1.0);
  EXPECT_EQ(r[table.ColumnIndex("classical_pxy")], 7.0);
  EXPECT_EQ(r[table.ColumnIndex("classical_pyth")], 8.0);
  EXPECT_EQ(r[table.ColumnIndex("selective_nfeat")], 5.0);
  EXPECT_TRUE(std::isnan(r[table.ColumnIndex("classical_nees")]));
  EXPECT_EQ(r[table.ColumnIndex("selective_nees")], 2.5);
  // Undefined values are empty fields, not "nan".
  EXPECT_EQ(ReadText(path).find("nan"), std::string::npos);
}

TEST(RowsTest, ExplorerSnapshotsRoundTrip) {
  const std::string path = rundir::PathIn(FreshDir("explorer"), rundir::kExplorerFile);
  ExplorerSnapshot first;
  first.t_s = 0.0;
  first.frontier = {{1.0, 2.0}, {3.0, 4.0}};
  first.goal = Eigen::Vector2d(3.0, 4.0);
  first.path = {{0.0, 0.0}, {1.5, 2.0}, {3.0, 4.0}};
  ExplorerSnapshot second;
  second.t_s = 0.5;
  second.frontier = {{-1.0, 0.25}};
  {
    CsvWriter writer(path, ExplorerColumns());
    AddExplorerRows(first, &writer);
    AddExplorerRows(second, &writer);
  }
  const std::vector<ExplorerSnapshot> read = ReadExplorerCsv(path);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].frontier, first.frontier);
  ASSERT_TRUE(read[0].goal.has_value());
  EXPECT_EQ(*read[0].goal, *first.goal);
  EXPECT_EQ(read[0].path, first.path);
  EXPECT_EQ(read[1].t_s, 0.5);
  EXPECT_EQ(read[1].frontier, second.frontier);
  EXPECT_FALSE(read[1].goal.has_value());
  EXPECT_TRUE(ReadExplorerCsv(path + ".missing").empty());
}

// Every field of a trajectory row, distinct from the others and from the
// defaults, so that a reader taking the wrong column fails.
TrajectoryRow DistinctRow(double t_s, int k) {
  TrajectoryRow row;
  row.t_s = t_s;
  row.X_WR_true = Pose2(1.0 + k, 2.0 + k, 0.25);
  row.X_WR_odometry = Pose2(3.0 + k, 4.0 + k, -0.5);
  row.command = {0.3, -0.1 - k};
  row.explored = k == 0 ? kNaN : 0.75;
  for (int f = 0; f < 2; ++f) {
    FilterRow filter;
    const double base = 10.0 * (f + 1) + 100.0 * k;
    filter.X_WR = Pose2(base + 0.1, base + 0.2, 0.1 * (f + 1));
    filter.P << base + 1, base + 2, base + 3, base + 2, base + 4, base + 5, base + 3, base + 5,
        base + 6;
    filter.num_features = 7 + f + k;
    filter.num_matched = 17 + f + k;
    filter.num_updated = 27 + f + k;
    filter.processing_us = base + 7;
    filter.period_s = base + 8;
    filter.open_loop_s = base + 9;
    filter.nees = f == 0 && k == 0 ? kNaN : base + 10;
    filter.processed = (f + k) % 2 == 0;
    row.filters.push_back(filter);
  }
  return row;
}

void ExpectSamePose(const Pose2& a, const Pose2& b) {
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.theta, b.theta);
}

// Equal, NaN equal to NaN.
void ExpectSameValue(double a, double b) {
  if (std::isnan(b)) {
    EXPECT_TRUE(std::isnan(a)) << a;
  } else {
    EXPECT_EQ(a, b);
  }
}

TEST(RowsTest, TrajectoryRowsReadBackAsWritten) {
  const std::string path = rundir::PathIn(FreshDir("trajectory_rows"), rundir::kTrajectoryFile);
  const std::vector<TrajectoryRow> written = {DistinctRow(0.0, 0), DistinctRow(0.1, 1)};
  {
    CsvWriter writer(path, TrajectoryColumns());
    for (const TrajectoryRow& row : written) AddTrajectoryRow(row, &writer);
  }
  const std::vector<TrajectoryRow> read = ReadTrajectoryRows(path);
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t k = 0; k < read.size(); ++k) {
    SCOPED_TRACE("row " + std::to_string(k));
    const TrajectoryRow& a = read[k];
    const TrajectoryRow& b = written[k];
    EXPECT_EQ(a.t_s, b.t_s);
    ExpectSamePose(a.X_WR_true, b.X_WR_true);
    ExpectSamePose(a.X_WR_odometry, b.X_WR_odometry);
    EXPECT_EQ(a.command.v_mps, b.command.v_mps);
    EXPECT_EQ(a.command.w_radps, b.command.w_radps);
    ExpectSameValue(a.explored, b.explored);
    ASSERT_EQ(a.filters.size(), 2u);
    for (int f = 0; f < 2; ++f) {
      SCOPED_TRACE("filter " + std::to_string(f));
      const FilterRow& fa = a.filters[f];
      const FilterRow& fb = b.filters[f];
      ExpectSamePose(fa.X_WR, fb.X_WR);
      EXPECT_EQ(fa.P, fb.P);
      EXPECT_EQ(fa.num_features, fb.num_features);
      EXPECT_EQ(fa.num_matched, fb.num_matched);
      EXPECT_EQ(fa.num_updated, fb.num_updated);
      EXPECT_EQ(fa.processing_us, fb.processing_us);
      EXPECT_EQ(fa.period_s, fb.period_s);
      EXPECT_EQ(fa.open_loop_s, fb.open_loop_s);
      ExpectSameValue(fa.nees, fb.nees);
      EXPECT_EQ(fa.processed, fb.processed);
    }
  }
}

// Any number of filters, named in the header: read back by name, in order.
TEST(RowsTest, TrajectoryRowsOfNamedFiltersReadTheirNames) {
  const std::string path = rundir::PathIn(FreshDir("named_filters"), rundir::kTrajectoryFile);
  const std::vector<std::string> names = {"selective", "dead_reckoning", "ekf_max_3"};
  TrajectoryRow row = DistinctRow(0.0, 0);
  row.filters.push_back(row.filters[0]);
  row.filters[2].X_WR = Pose2(7.0, 8.0, 0.5);
  {
    CsvWriter writer(path, TrajectoryColumns(names));
    AddTrajectoryRow(row, &writer);
  }
  const std::vector<TrajectoryRow> read = ReadTrajectoryRows(path);
  ASSERT_EQ(read.size(), 1u);
  ASSERT_EQ(read[0].filters.size(), 3u);
  for (std::size_t f = 0; f < names.size(); ++f) EXPECT_EQ(read[0].filters[f].name, names[f]);
  EXPECT_EQ(read[0].filters[2].X_WR.x, 7.0);
}

TEST(RowsTest, TrajectoryRowsOfARecordingHaveNoFilters) {
  const std::string dir = FreshDir("trajectory_recorded");
  // Without truth and explored fraction, as mjslam import writes it.
  std::ofstream(rundir::PathIn(dir, rundir::kTrajectoryFile))
      << "t,true_x,true_y,true_th,odom_x,odom_y,odom_th,cmd_v,cmd_w\n"
         "0,,,,1,2,0.5,0.2,0\n0.1,,,,1.01,2,0.5,0.2,0.1\n";
  const std::vector<TrajectoryRow> read = ReadTrajectoryRows(rundir::PathIn(dir, rundir::kTrajectoryFile));
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[1].t_s, 0.1);
  EXPECT_TRUE(std::isnan(read[1].X_WR_true.x));
  EXPECT_EQ(read[1].X_WR_odometry.x, 1.01);
  EXPECT_EQ(read[1].X_WR_odometry.theta, 0.5);
  EXPECT_EQ(read[1].command.w_radps, 0.1);
  EXPECT_TRUE(std::isnan(read[1].explored));
  EXPECT_TRUE(read[1].filters.empty());
}

// The message of the runtime_error that `read` throws ("" if none).
template <typename Read>
std::string ErrorOf(const Read& read) {
  try {
    read();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(RowsTest, TrajectoryRowsRefuseBadFieldsNamingFileLineAndColumn) {
  const std::string dir = FreshDir("trajectory_bad");
  const std::string good = rundir::PathIn(dir, "good.csv");
  {
    CsvWriter writer(good, TrajectoryColumns());
    AddTrajectoryRow(DistinctRow(0.0, 0), &writer);
    AddTrajectoryRow(DistinctRow(0.1, 1), &writer);
  }
  const std::string text = ReadText(good);
  const std::size_t header_end = text.find('\n') + 1;
  const std::size_t row_end = text.find('\n', header_end) + 1;
  // Field `column` of the second row (line 3) replaced by `value`.
  auto with_field = [&](const std::string& column, const std::string& value) {
    const std::vector<std::string> columns = TrajectoryColumns();
    const std::size_t index = std::find(columns.begin(), columns.end(), column) - columns.begin();
    std::vector<std::string> fields;
    std::stringstream row(text.substr(row_end, text.size() - row_end - 1));
    for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
    fields.at(index) = value;
    std::string line;
    for (std::size_t i = 0; i < fields.size(); ++i) line += (i > 0 ? "," : "") + fields[i];
    const std::string path = rundir::PathIn(dir, column + "_" + value + ".csv");
    std::ofstream(path) << text.substr(0, row_end) << line << "\n";
    return path;
  };
  struct Case {
    std::string column, value;
  };
  for (const Case& c : {Case{"classical_nfeat", "2.5"}, Case{"selective_nmatched", "-1"},
                        Case{"selective_nupdated", ""}, Case{"classical_processed", "2"},
                        Case{"selective_processed", "0.5"}}) {
    const std::string path = with_field(c.column, c.value);
    EXPECT_EQ(ErrorOf([&] { ReadTrajectoryRows(path); }).rfind(path + ":3: column " + c.column + ": ", 0), 0u)
        << c.column << " = '" << c.value << "': " << ErrorOf([&] { ReadTrajectoryRows(path); });
  }
  // A column twice, one unknown, one missing.
  std::string twice = text;
  twice.replace(twice.find("selective_th"), 12, "selective_y");
  std::ofstream(dir + "/twice.csv") << twice;
  EXPECT_NE(ErrorOf([&] { ReadTrajectoryRows(dir + "/twice.csv"); }).find("column selective_y: twice"),
            std::string::npos);
  std::string missing = text;
  missing.replace(missing.find("classical_pyy"), 13, "classical_pyx");
  std::ofstream(dir + "/unknown.csv") << missing;
  EXPECT_NE(ErrorOf([&] { ReadTrajectoryRows(dir + "/unknown.csv"); }).find("column classical_pyx"),
            std::string::npos);
  std::string extra;
  std::stringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    extra += line + (extra.empty() ? ",extra\n" : ",1\n");
  }
  std::ofstream(dir + "/extra.csv") << extra;
  EXPECT_NE(ErrorOf([&] { ReadTrajectoryRows(dir + "/extra.csv"); }).find("column extra"),
            std::string::npos);
  // Only the recorded columns' checks of ReadTrajectoryCsv before.
  const std::string bad_time = with_field("t", "0");
  EXPECT_EQ(ErrorOf([&] { ReadTrajectoryRows(bad_time); }).rfind(bad_time + ":3: column t: ", 0), 0u);
  EXPECT_EQ(ErrorOf([&] { ReadTrajectoryRows(good); }), "");
}

// A run from before the optional columns, its columns in another order: the
// fields by name, the missing ones NaN (processed: true); without a
// required column of a filter, an error naming it.
TEST(RowsTest, TrajectoryRowsOfAnOlderRunReadTheColumnsByName) {
  const std::string dir = FreshDir("trajectory_older");
  const std::string header = "t,true_x,true_y,true_th,odom_x,odom_y,odom_th,cmd_v,cmd_w";
  std::string filters, values;
  for (const std::string& name : DefaultFilterNames()) {
    // The pose last, after the counts.
    for (const char* suffix : {"pxx", "pxy", "pxth", "pyy", "pyth", "pthth", "nfeat", "nmatched",
                               "nupdated", "us", "x", "y", "th"}) {
      filters += "," + name + "_" + suffix;
    }
    values += name == "classical" ? ",1,2,3,4,5,6,7,8,9,10,11,12,0.5" : ",21,22,23,24,25,26,27,28,29,30,31,32,-0.5";
  }
  const std::string path = rundir::PathIn(dir, "older.csv");
  std::ofstream(path) << header << filters << "\n0,1,2,0,1,2,0,0.2,0" << values << "\n";
  const std::vector<TrajectoryRow> read = ReadTrajectoryRows(path);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_TRUE(std::isnan(read[0].explored));
  ASSERT_EQ(read[0].filters.size(), 2u);
  const FilterRow& selective = read[0].filters[1];
  ExpectSamePose(selective.X_WR, Pose2(31.0, 32.0, -0.5));
  Eigen::Matrix3d P;
  P << 21, 22, 23, 22, 24, 25, 23, 25, 26;
  EXPECT_EQ(selective.P, P);
  EXPECT_EQ(selective.num_features, 27);
  EXPECT_EQ(selective.num_matched, 28);
  EXPECT_EQ(selective.num_updated, 29);
  EXPECT_EQ(selective.processing_us, 30.0);
  EXPECT_TRUE(std::isnan(selective.period_s));
  EXPECT_TRUE(std::isnan(selective.open_loop_s));
  EXPECT_TRUE(std::isnan(selective.nees));
  EXPECT_TRUE(selective.processed);
  ExpectSamePose(read[0].filters[0].X_WR, Pose2(11.0, 12.0, 0.5));
  EXPECT_EQ(read[0].filters[0].num_features, 7);

  // Without selective_pyy.
  std::string cut_filters = filters;
  cut_filters.erase(cut_filters.find(",selective_pyy"), 14);
  std::string cut_values = values;
  cut_values.erase(cut_values.find(",24,"), 3);
  std::ofstream(dir + "/cut.csv") << header << cut_filters << "\n0,1,2,0,1,2,0,0.2,0" << cut_values << "\n";
  EXPECT_NE(ErrorOf([&] { ReadTrajectoryRows(dir + "/cut.csv"); }).find("no column selective_pyy"),
            std::string::npos);
}

TEST(RowsTest, ScanRowsReadBackAsWritten) {
  const std::string path = rundir::PathIn(FreshDir("scan_rows"), rundir::kScansFile);
  {
    CsvWriter writer(path, ScanColumns(3));
    AddScanRow(0.1, Pose2(1.0, 2.0, 0.5), {3.0, 4.5, 30.0}, &writer);
    AddScanRow(0.2, Pose2(1.5, 2.5, -0.5), {0.0, 1.0, 2.0}, &writer);
  }
  const std::vector<ScanRow> read = ReadScanRows(path);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].t_s, 0.1);
  ExpectSamePose(read[0].X_WS, Pose2(1.0, 2.0, 0.5));
  EXPECT_EQ(read[0].ranges_m, (std::vector<double>{3.0, 4.5, 30.0}));
  EXPECT_EQ(read[1].t_s, 0.2);
  ExpectSamePose(read[1].X_WS, Pose2(1.5, 2.5, -0.5));
  EXPECT_EQ(read[1].ranges_m, (std::vector<double>{0.0, 1.0, 2.0}));
  // A negative range, named by file, line and column.
  std::ofstream(path + ".bad") << "t,x,y,th,r0,r1\n0.1,1,2,0,3,4\n0.2,1,2,0,3,-4\n";
  EXPECT_EQ(ErrorOf([&] { ReadScanRows(path + ".bad"); }).rfind(path + ".bad:3: column r1: ", 0), 0u);
}

TEST(RowsTest, ReferenceRowsReadTheColumnsInOrder) {
  const std::string dir = FreshDir("reference_rows");
  const std::string path = rundir::PathIn(dir, rundir::kReferenceFile);
  std::ofstream(path) << HeaderLine(ReferenceColumns()) << "0.5,1,2,0.25\n0.75,3,4,-0.5\n";
  const std::vector<ReferenceRow> read = ReadReferenceRows(path);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].t_s, 0.5);
  ExpectSamePose(read[0].X_WR, Pose2(1.0, 2.0, 0.25));
  EXPECT_EQ(read[1].t_s, 0.75);
  ExpectSamePose(read[1].X_WR, Pose2(3.0, 4.0, -0.5));
  // Columns out of order, an extra column, times not increasing.
  std::ofstream(dir + "/swapped.csv") << "t,y,x,th\n0.5,1,2,0.25\n";
  EXPECT_NE(ErrorOf([&] { ReadReferenceRows(dir + "/swapped.csv"); }), "");
  std::ofstream(dir + "/extra.csv") << "t,x,y,th,z\n0.5,1,2,0.25,0\n";
  EXPECT_NE(ErrorOf([&] { ReadReferenceRows(dir + "/extra.csv"); }).find("column z"), std::string::npos);
  std::ofstream(dir + "/times.csv") << "t,x,y,th\n0.5,1,2,0.25\n0.5,1,2,0.25\n";
  EXPECT_EQ(ErrorOf([&] { ReadReferenceRows(dir + "/times.csv"); }).rfind(dir + "/times.csv:3: column t: ", 0), 0u);
}

TEST(RecordingTest, ReadsStepsScansAndTheMountFromTheFirstScan) {
  const std::string dir = FreshDir("recording");
  // Two steps, a scan at the second; the laser 0.1 m ahead of R.
  std::ofstream(rundir::PathIn(dir, rundir::kTrajectoryFile))
      << "t,true_x,true_y,true_th,odom_x,odom_y,odom_th,cmd_v,cmd_w\n"
         "0,1,2,0,1,2,0,0.2,0\n0.1,1,2,0,1.01,2,0,0.2,0.1\n";
  std::ofstream(rundir::PathIn(dir, rundir::kScansFile)) << "t,x,y,th,r0,r1\n0.1,1.1,2,0,3,4\n";
  const Recording recording(rundir::PathIn(dir, rundir::kScansFile), "", 2);
  EXPECT_EQ(recording.trajectory_path(), rundir::PathIn(dir, rundir::kTrajectoryFile));
  ASSERT_EQ(recording.num_steps(), 2u);
  EXPECT_NEAR(recording.X_RS().x, 0.1, 1e-12);
  EXPECT_EQ(recording.Step(0).scan_ranges_m, nullptr);
  const RecordedStep step = recording.Step(1);
  ASSERT_NE(step.scan_ranges_m, nullptr);
  EXPECT_EQ(*step.scan_ranges_m, (std::vector<double>{3.0, 4.0}));
  EXPECT_EQ(step.X_WR_odometry.x, 1.01);
  EXPECT_EQ(step.command.w_radps, 0.1);
  EXPECT_TRUE(std::isnan(step.explored));  // the recording has no explored column

  // Another beam count, or a trajectory whose columns are out of order.
  EXPECT_THROW(Recording(rundir::PathIn(dir, rundir::kScansFile), "", 3), std::runtime_error);
  std::ofstream(dir + "/other.csv")
      << "t,true_y,true_x,true_th,odom_x,odom_y,odom_th,cmd_v,cmd_w\n0,1,2,0,1,2,0,0,0\n";
  EXPECT_THROW(Recording(rundir::PathIn(dir, rundir::kScansFile), dir + "/other.csv", 2), std::runtime_error);
}

}  // namespace
}  // namespace mjslam::rundir
