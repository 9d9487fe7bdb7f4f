// The closed-loop engine on a short run of the default world: the clock holds
// each command for the driving filter's command period, and the same loop on
// a recording of the run gives the filters the same records bit for bit.
#include <cmath>
#include <filesystem>
#include <vector>

#include <gtest/gtest.h>

#include "app/closed_loop.h"
#include "app/run_config.h"
#include "rundir/csv_writer.h"
#include "rundir/layout.h"
#include "rundir/manifest.h"
#include "rundir/recording.h"
#include "rundir/rows.h"

namespace mjslam::app {
namespace {

namespace fs = std::filesystem;

// 3 s of the default world, the explorer driving from the selective filter
// at once (no initial turn), whose processing takes 0.25 s on every step (a
// scan on every step, no cost per correction): a command period of 3
// control steps.
RunConfig ShortConfig() {
  RunConfig config = LoadRunConfig(std::string(MJSLAM_SOURCE_DIR) + "/configs/default.yaml",
                                   {"run.duration_s=3", "explorer.initial_turn_deg=0", "control.model_base_s=0.25",
                                    "control.model_s_per_update_per_n2=0"});
  config.ValidateOrThrow();
  return config;
}

TEST(ClosedLoopTest, HoldsEachCommandForTheDrivingFiltersPeriod) {
  const RunConfig config = ShortConfig();
  ClosedLoop loop(config);
  ASSERT_EQ(loop.num_steps(), 31);
  std::vector<rundir::TrajectoryRow> rows;
  while (!loop.Done()) rows.push_back(loop.Step().row);
  ASSERT_EQ(rows.size(), 31u);
  int changes = 0;
  for (std::size_t k = 1; k < rows.size(); ++k) {
    EXPECT_NEAR(rows[k].t_s, 0.1 * k, 1e-12);
    ASSERT_EQ(rows[k].filters.size(), 2u);
    EXPECT_DOUBLE_EQ(rows[k].filters[1].period_s, 0.30000000000000004);
    const bool changed = rows[k].command.v_mps != rows[k - 1].command.v_mps ||
                         rows[k].command.w_radps != rows[k - 1].command.w_radps;
    // A new command only every third step.
    if (k % 3 != 0) {
      EXPECT_FALSE(changed) << "step " << k;
    }
    changes += changed ? 1 : 0;
  }
  EXPECT_GT(changes, 2);  // the robot is driven, or the test proves nothing
}

TEST(ClosedLoopTest, TheLoopOnARecordingGivesTheFiltersTheSameRecords) {
  const RunConfig config = ShortConfig();
  const std::string dir = (fs::temp_directory_path() / "mjslam_closed_loop_test").string();
  fs::remove_all(dir);
  fs::create_directories(dir);

  // The simulated loop, its recording written as a run writes it.
  std::vector<rundir::TrajectoryRow> simulated;
  {
    ClosedLoop loop(config);
    rundir::ManifestWriter manifest(dir, nlohmann::json::object());
    manifest.SetLaserMount(loop.X_RS());
    manifest.Finish("completed");
    rundir::CsvWriter trajectory(rundir::PathIn(dir, rundir::kTrajectoryFile),
                                 rundir::TrajectoryColumns());
    rundir::CsvWriter scans(rundir::PathIn(dir, rundir::kScansFile),
                            rundir::ScanColumns(config.laser.num_beams));
    while (!loop.Done()) {
      const LoopStep& step = loop.Step();
      if (step.record.has_scan) {
        rundir::AddScanRow(step.record.t_s, step.X_WS_true, step.record.scan.ranges_m, &scans);
      }
      rundir::AddTrajectoryRow(step.row, &trajectory);
      simulated.push_back(step.row);
    }
  }

  // The recorded loop on it.
  const rundir::Recording recording(rundir::PathIn(dir, rundir::kScansFile), "",
                                    config.laser.num_beams);
  ClosedLoop replay(config, recording);
  std::size_t k = 0;
  for (; !replay.Done(); ++k) {
    const rundir::TrajectoryRow& row = replay.Step().row;
    ASSERT_LT(k, simulated.size());
    EXPECT_EQ(row.command.v_mps, simulated[k].command.v_mps) << "step " << k;
    for (int f = 0; f < 2; ++f) {
      const rundir::FilterRow& a = row.filters[f];
      const rundir::FilterRow& b = simulated[k].filters[f];
      EXPECT_EQ(a.X_WR.x, b.X_WR.x) << "step " << k << " filter " << f;
      EXPECT_EQ(a.X_WR.theta, b.X_WR.theta) << "step " << k << " filter " << f;
      EXPECT_EQ(a.P, b.P) << "step " << k << " filter " << f;
      EXPECT_EQ(a.num_matched, b.num_matched) << "step " << k << " filter " << f;
    }
  }
  EXPECT_EQ(k, simulated.size());
  EXPECT_GT(simulated.back().filters[1].num_features, 0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace mjslam::app
