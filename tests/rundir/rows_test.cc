// The row writers and readers of rundir/rows.h and rundir/recording.h:
// trajectory rows in the documented columns, explorer snapshots written and
// read back, a recording read for a replay.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

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
