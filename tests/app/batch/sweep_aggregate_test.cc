// The sweep aggregate on hand-made run directories: the optional f_nees and
// f_period columns are used when present, runs of different lengths, the
// bounds for the runs that reach each step, verdicts.
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "app/batch/sweep.h"
#include "common/chi_square.h"
#include "rundir/csv_reader.h"
#include "rundir/layout.h"

namespace mjslam::app {
namespace {

namespace fs = std::filesystem;
using rundir::CsvTable;
using rundir::ReadCsv;

std::string FreshDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / "mjslam_aggregate_test" / std::to_string(::getpid()) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

// A trajectory.csv with the given NEES per step for both filters (columns
// f_nees), the truth and both estimates at the origin with a unit covariance,
// 100 and 50 us per step and, when `with_period`, f_period and f_open_loop
// columns (runs from before them have none).
void WriteRun(const std::string& dir, const std::vector<double>& classical_nees,
              const std::vector<double>& selective_nees, bool with_period) {
  fs::create_directories(dir);
  std::ofstream out(rundir::PathIn(dir, rundir::kTrajectoryFile));
  out << "t,true_x,true_y,true_th,odom_x,odom_y,odom_th,cmd_v,cmd_w";
  for (const char* f : {"classical", "selective"}) {
    for (const char* suffix : {"x", "y", "th", "pxx", "pxy", "pxth", "pyy", "pyth", "pthth",
                               "nfeat", "nmatched", "nupdated", "us", "nees"}) {
      out << "," << f << "_" << suffix;
    }
  }
  if (with_period) {
    out << ",classical_period,selective_period,classical_open_loop,selective_open_loop";
  }
  out << "\n";
  for (std::size_t k = 0; k < classical_nees.size(); ++k) {
    out << 0.1 * k << ",0,0,0,0,0,0,0,0";
    out << ",0,0,0,1,0,0,1,0,1,0,0,0,100," << classical_nees[k];
    out << ",0,0,0,1,0,0,1,0,1,0,0,0,50," << selective_nees[k];
    // The classical filter holds its command 0.3 s at step 2 (0.2 s open
    // loop from then on), else 0.1 s.
    if (with_period) out << "," << (k == 2 ? 0.3 : 0.1) << ",0.1," << (k >= 2 ? 0.2 : 0.0) << ",0";
    out << "\n";
  }
}

TEST(SweepAggregateTest, AveragesTheNeesColumnsAgainstTheBoundsOfTheRunsPresent) {
  const std::string dir = FreshDir("aggregate");
  const double nan = std::nan("");
  // Step 0 undefined (known start); run b is one step shorter.
  WriteRun(dir + "/a", {nan, 3.0, 30.0, 3.0}, {nan, 2.0, 3.0, 0.01}, true);
  WriteRun(dir + "/b", {nan, 3.0, 30.0}, {nan, 4.0, 3.0}, true);
  SweepOptions options;
  const nlohmann::json summary = AggregateSweep({dir + "/a", dir + "/b"}, dir, options);

  const CsvTable nees = ReadCsv(dir + "/nees.csv");
  ASSERT_EQ(nees.rows.size(), 3u);  // steps 1, 2, 3
  EXPECT_NEAR(nees.rows[0][0], 0.1, 1e-12);
  EXPECT_EQ(nees.rows[0][1], 3.0);
  EXPECT_EQ(nees.rows[0][2], 3.0);  // (2 + 4) / 2
  EXPECT_EQ(nees.rows[0][5], 2.0);
  EXPECT_EQ(nees.rows[2][5], 1.0);  // only run a reaches step 3
  const Interval two = AverageNeesBounds(2, 3);
  const Interval one = AverageNeesBounds(1, 3);
  EXPECT_EQ(nees.rows[0][3], two.lower);
  EXPECT_EQ(nees.rows[0][4], two.upper);
  EXPECT_EQ(nees.rows[2][3], one.lower);

  // Classical: inside, above (30), inside; selective: inside, inside, below.
  const nlohmann::json& c = summary["filters"]["classical"];
  const nlohmann::json& s = summary["filters"]["selective"];
  EXPECT_NEAR(c["fraction_inside"].get<double>(), 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(c["fraction_above"].get<double>(), 1.0 / 3.0, 1e-12);
  EXPECT_EQ(c["verdict"], "overconfident");
  EXPECT_NEAR(s["fraction_below"].get<double>(), 1.0 / 3.0, 1e-12);
  EXPECT_EQ(s["verdict"], "underconfident");
  EXPECT_EQ(summary["sweep"]["steps"], 3);
  // Processing: mean over runs of the summed microseconds.
  EXPECT_NEAR(c["measured_processing_s"].get<double>(), (400e-6 + 300e-6) / 2, 1e-15);
  EXPECT_TRUE(c["processing_s"].is_null());  // these runs have no summary.json
  // Open loop: 0.2 s beyond the period once per run.
  EXPECT_NEAR(c["open_loop_s"].get<double>(), 0.2, 1e-12);
  EXPECT_NEAR(s["open_loop_s"].get<double>(), 0.0, 1e-12);
  EXPECT_EQ(c["max_period_s"], 0.3);

  // Lenient verdict threshold: the classical filter passes at 2/3.
  options.min_fraction_inside = 0.6;
  EXPECT_EQ(AggregateSweep({dir + "/a", dir + "/b"}, dir, options)["filters"]["classical"]["verdict"],
            "consistent");
}

TEST(SweepAggregateTest, NoPeriodColumnsGiveNoOpenLoopTime) {
  const std::string dir = FreshDir("no_period");
  WriteRun(dir + "/a", {std::nan(""), 3.0}, {std::nan(""), 3.0}, false);
  const nlohmann::json summary = AggregateSweep({dir + "/a"}, dir, SweepOptions{});
  EXPECT_TRUE(summary["filters"]["classical"]["open_loop_s"].is_null());
  EXPECT_TRUE(summary["filters"]["classical"]["max_period_s"].is_null());
  EXPECT_EQ(summary["filters"]["classical"]["verdict"], "consistent");
}

}  // namespace
}  // namespace mjslam::app
