#include <filesystem>
#include <fstream>
#include <string>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "app/engine/run_config.h"
#include "config/config.h"

namespace mjslam::app {
namespace {

namespace fs = std::filesystem;

TEST(RunConfigTest, EveryShippedConfigLoadsAndValidates) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(MJSLAM_SOURCE_DIR) / "configs")) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    const RunConfig config = LoadRunConfig(entry.path().string(), {});
    EXPECT_NO_THROW(config.ValidateOrThrow());
    EXPECT_TRUE(fs::exists(config.run.world)) << config.run.world;
    EXPECT_TRUE(fs::exists(config.run.robot_model)) << config.run.robot_model;
    ++count;
  }
  EXPECT_GE(count, 1);
}

TEST(RunConfigTest, ResolvedConfigLoadsBackIdentically) {
  const std::string path = std::string(MJSLAM_SOURCE_DIR) + "/configs/default.yaml";
  const RunConfig config = LoadRunConfig(path, {"laser.range_noise_std_m=0.0123"});
  EXPECT_EQ(config.laser.range_noise_std_m, 0.0123);
  const std::string text = config::ToYaml(config);
  const RunConfig again = config::LoadConfigString<RunConfig>(text, "resolved");
  EXPECT_EQ(config::ToYaml(again), text);
}

TEST(RunConfigTest, PathsAreRelativeToTheConfigFile) {
  const std::string path = std::string(MJSLAM_SOURCE_DIR) + "/configs/default.yaml";
  const RunConfig config = LoadRunConfig(path, {});
  EXPECT_TRUE(fs::path(config.run.world).is_absolute());
  EXPECT_EQ(fs::path(config.run.world).parent_path().filename(), "worlds");
}

TEST(RunConfigTest, LaserRateMustDivideControlRate) {
  const std::string path = std::string(MJSLAM_SOURCE_DIR) + "/configs/default.yaml";
  try {
    LoadRunConfig(path, {"laser.rate_hz=3"});
    FAIL() << "expected an error";
  } catch (const std::exception& error) {
    EXPECT_NE(std::string(error.what()).find("laser.rate_hz"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("(got 3)"), std::string::npos) << error.what();
  }
}

// duration_s * control_rate_hz is a step count held in an int: 1e12 s
// overflowed to a run of 0 steps that said "completed".
TEST(RunConfigTest, DurationBeyondOneHundredMillionStepsIsRefused) {
  const std::string path = std::string(MJSLAM_SOURCE_DIR) + "/configs/default.yaml";
  EXPECT_NO_THROW(LoadRunConfig(path, {"run.duration_s=1e7"}));  // 1e8 steps at 10 Hz
  for (const std::string value : {"1e12", "1.0000001e7", ".inf"}) {
    try {
      LoadRunConfig(path, {"run.duration_s=" + value});
      ADD_FAILURE() << "expected an error for " << value;
    } catch (const std::exception& error) {
      EXPECT_NE(std::string(error.what()).find("run.duration_s: expected at most 1e8 control steps"),
                std::string::npos)
          << error.what();
    }
  }
}

TEST(RunConfigTest, FiltersMustPredictTheRobotsPointH) {
  const std::string path = std::string(MJSLAM_SOURCE_DIR) + "/configs/default.yaml";
  EXPECT_NO_THROW(LoadRunConfig(
      path, {"robot.control_point_offset_m=0.15", "slam.ekf.control_point_offset_m=0.15"}));
  try {
    LoadRunConfig(path, {"robot.control_point_offset_m=0.15"});
    FAIL() << "expected an error";
  } catch (const std::exception& error) {
    EXPECT_NE(std::string(error.what()).find("slam.ekf.control_point_offset_m"), std::string::npos)
        << error.what();
  }
}

TEST(RunConfigTest, FiltersSplitTheOdometryWithTheRobotsTrack) {
  const std::string path = std::string(MJSLAM_SOURCE_DIR) + "/configs/default.yaml";
  EXPECT_NO_THROW(
      LoadRunConfig(path, {"robot.axle_track_m=0.34", "slam.ekf.axle_track_m=0.34"}));
  try {
    LoadRunConfig(path, {"robot.axle_track_m=0.34"});
    FAIL() << "expected an error";
  } catch (const std::exception& error) {
    EXPECT_NE(std::string(error.what()).find("slam.ekf.axle_track_m"), std::string::npos)
        << error.what();
  }
}

TEST(RunConfigTest, AllProblemsReportedAtOnceWithPositions) {
  const fs::path dir = fs::temp_directory_path() / "mjslam_run_config_test";
  fs::create_directories(dir);
  const fs::path path = dir / "bad.yaml";
  std::ofstream(path) << "run:\n  seed: 3\n  duration_s: -1\nlaser:\n  max_range_m: 0\n  bogus: 1\n";
  try {
    LoadRunConfig(path.string(), {});
    FAIL() << "expected an error";
  } catch (const std::exception& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find(path.string() + ":3:"), std::string::npos) << what;
    EXPECT_NE(what.find("run.duration_s"), std::string::npos) << what;
    EXPECT_NE(what.find("laser.max_range_m"), std::string::npos) << what;
    EXPECT_NE(what.find("laser.bogus"), std::string::npos) << what;
  }
}

// The message of the error that loading `yaml` (over configs/default.yaml)
// throws; `path` receives the file's name.
std::string ProcessModelErrorOf(const std::string& yaml, std::string* path,
                                const std::vector<std::string>& overrides = {}) {
  const fs::path dir = fs::temp_directory_path() / "mjslam_run_config_test";
  fs::create_directories(dir);
  *path = (dir / "process_model.yaml").string();
  std::ofstream(*path) << "base: " << MJSLAM_SOURCE_DIR << "/configs/default.yaml\n" << yaml;
  try {
    LoadRunConfig(*path, overrides);
  } catch (const std::exception& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected an error for:\n" << yaml;
  return {};
}

TEST(RunConfigTest, ProcessModelIsATaggedChoice) {
  std::string path;
  // A key of the other kind: file:line, the key and both kinds.
  std::string what = ProcessModelErrorOf(
      "slam:\n  ekf:\n    process_model:\n      noise:\n        v_std_mps: 0.1\n", &path);
  EXPECT_NE(what.find(path + ":6:9: slam.ekf.process_model.noise.v_std_mps: a key of kind "
                             "'command', not of kind 'odometry'"),
            std::string::npos)
      << what;
  // The flat keys of before: at their line, with the key that replaced each.
  what = ProcessModelErrorOf(
      "slam:\n  ekf:\n    input: odometry\n    odometry_noise: {distance_noise_std_m: 0}\n"
      "    lateral_skid_s: 0\n    process_model:\n      noise: {heading_noise_std_rad: 0}\n",
      &path);
  EXPECT_NE(what.find(path + ":4:5: slam.ekf.input: a retired key, now "
                             "slam.ekf.process_model.kind"),
            std::string::npos)
      << what;
  EXPECT_NE(what.find(path + ":5:5: slam.ekf.odometry_noise: a retired key, now "
                             "slam.ekf.process_model.noise (with process_model.kind: odometry"),
            std::string::npos)
      << what;
  EXPECT_NE(what.find(path + ":6:5: slam.ekf.lateral_skid_s: a retired key, now "
                             "slam.ekf.process_model.lateral.skid_s"),
            std::string::npos)
      << what;
  EXPECT_NE(what.find(path + ":8:15: slam.ekf.process_model.noise.heading_noise_std_rad: a "
                             "retired key, now slam.ekf.process_model.noise.heading_std_rad"),
            std::string::npos)
      << what;
  // Likewise from --set.
  what = ProcessModelErrorOf("", &path, {"slam.ekf.motion_integration=euler"});
  EXPECT_NE(what.find("--set slam.ekf.motion_integration=euler: slam.ekf.motion_integration: a "
                      "retired key, now slam.ekf.process_model.integration"),
            std::string::npos)
      << what;
  // --set of the kind starts the other kind from its built-in values.
  const std::string defaults = std::string(MJSLAM_SOURCE_DIR) + "/configs/default.yaml";
  const RunConfig command =
      LoadRunConfig(defaults, {"slam.ekf.process_model.kind=command",
                               "slam.ekf.process_model.noise.change_fraction=0"});
  const auto* model = std::get_if<slam::CommandProcessModel>(&command.slam.ekf.process_model);
  ASSERT_NE(model, nullptr);
  EXPECT_EQ(model->noise.change_fraction, 0.0);
  EXPECT_EQ(model->noise.v_std_mps, slam::CommandNoiseParams().v_std_mps);
  EXPECT_EQ(model->lateral.skid_s, slam::LateralMotionParams().skid_s);
}

}  // namespace
}  // namespace mjslam::app
