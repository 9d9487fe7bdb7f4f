// configs/paper.yaml, the paper's method as published: it runs, and the run's
// resolved config.yaml holds the paper's choice for every key it sets
// (docs/method.md, "configs/paper.yaml").
#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/engine/run_config.h"
#include "rundir/layout.h"
#include "rundir/summary.h"
#include "tests/integration/run_helpers.h"

namespace mjslam::testing {
namespace {

std::string PaperConfig() { return std::string(MJSLAM_SOURCE_DIR) + "/configs/paper.yaml"; }

// The keys paper.yaml turns to the paper's choice, checked on a loaded config.
void ExpectPaperChoices(const app::RunConfig& config) {
  const slam::EkfParams& ekf = config.slam.ekf;
  const auto* command = std::get_if<slam::CommandProcessModel>(&ekf.process_model);
  ASSERT_NE(command, nullptr);
  EXPECT_EQ(command->integration, "euler");
  EXPECT_EQ(command->lateral.slip_std_m_per_rad, 0.0);
  EXPECT_EQ(command->lateral.slip_std_m_per_sqrt_m, 0.0);
  EXPECT_EQ(command->lateral.skid_s, 0.0);
  EXPECT_EQ(command->noise.change_fraction, 0.0);
  EXPECT_EQ(ekf.line_match_max_gap_m, 0.0);
  EXPECT_EQ(ekf.self_calibration.wheel_slip_drift_std_per_sqrt_m, 0.0);
  EXPECT_TRUE(ekf.correct_corners_of_matched_lines);
  EXPECT_FALSE(ekf.corners_from_map_lines);
  EXPECT_FALSE(ekf.new_features_need_match);
  EXPECT_EQ(ekf.extra_line_rho_std_m, 0.0);
  EXPECT_EQ(ekf.extra_line_alpha_std_rad, 0.0);
  EXPECT_EQ(ekf.extra_corner_range_std_m, 0.0);
  EXPECT_EQ(ekf.extra_corner_bearing_std_rad, 0.0);
  EXPECT_EQ(ekf.jacobians, "current");
  EXPECT_EQ(ekf.max_updates, 2);
  EXPECT_EQ(ekf.selection_policy, "criterion");
  EXPECT_EQ(config.control.driver, "explorer");
  EXPECT_EQ(config.control.pose_source, "odometry");
}

TEST(PaperConfigTest, SetsEveryDepartureWithAKeyToThePapersChoice) {
  const app::RunConfig paper = app::LoadRunConfig(PaperConfig(), {});
  ExpectPaperChoices(paper);
  // And these are not the defaults: the file is what changes them.
  const app::RunConfig defaults = app::LoadRunConfig(DefaultConfig(), {});
  EXPECT_EQ(slam::IntegrationOf(defaults.slam.ekf.process_model), "exact");
  EXPECT_GT(slam::LateralOf(defaults.slam.ekf.process_model).skid_s, 0.0);
  EXPECT_GT(slam::LateralOf(defaults.slam.ekf.process_model).slip_std_m_per_rad, 0.0);
  EXPECT_GT(slam::CommandNoiseParams().change_fraction, 0.0);  // the built-in command noise
  EXPECT_FALSE(defaults.slam.ekf.correct_corners_of_matched_lines);
  EXPECT_TRUE(defaults.slam.ekf.corners_from_map_lines);
  EXPECT_TRUE(defaults.slam.ekf.new_features_need_match);
  EXPECT_NE(defaults.control.pose_source, "odometry");
}

TEST(PaperConfigTest, AShortRunCompletesWithThePapersResolvedConfig) {
  const std::string dir = FreshDir("paper");
  ASSERT_EQ(Shell(Program() + " run --quiet --no-render --config " + PaperConfig() +
                  " --duration 20 --out " + dir + " 2> " + dir + ".log"),
            0)
      << ReadText(dir + ".log");
  ExpectPaperChoices(app::LoadRunConfig(dir + "/" + rundir::kConfigFile, {}));
  const nlohmann::json summary = rundir::ReadSummary(dir);
  ASSERT_TRUE(summary.contains("run")) << summary.dump();
  EXPECT_EQ(summary["run"]["termination_reason"], "time_limit");
  EXPECT_EQ(summary["run"]["pose_source"], "odometry");
  EXPECT_NEAR(summary["run"]["duration_s"].get<double>(), 20.0, 1e-9);
  // Both filters ran and kept the pose (the paper's model holds 20 s).
  for (const char* name : {"classical", "selective"}) {
    const nlohmann::json& error = summary["filters"][name]["final_pose_error"];
    EXPECT_LT(std::hypot(error["x"].get<double>(), error["y"].get<double>()), 0.05) << name;
    EXPECT_GT(summary["filters"][name]["num_features"].get<int>(), 0) << name;
  }
}

}  // namespace
}  // namespace mjslam::testing
