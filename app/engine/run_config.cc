#include "app/engine/run_config.h"

#include <cmath>
#include <filesystem>

#include "config/config.h"
#include "slam/filter.h"

namespace mjslam::app {
namespace {

constexpr double kMaxControlSteps = 1e8;

}  // namespace

std::vector<ParamProblem> RunParams::Validate() const {
  ParamChecker check;
  check.Positive("duration_s", duration_s);
  check.Positive("control_rate_hz", control_rate_hz);
  check.Require(!world.empty(), "world", world, "a world MJCF file");
  check.Require(!robot_model.empty(), "robot_model", robot_model, "a robot MJCF file");
  return check.problems();
}

std::vector<ParamProblem> RunConfig::Validate() const {
  ParamChecker check;
  check.Merge("run", run.Validate());
  check.Merge("sim", sim.Validate());
  check.Merge("robot", robot.Validate());
  check.Merge("laser", laser.Validate());
  check.Merge("odometry", odometry.Validate());
  check.Merge("driver", driver.Validate());
  check.Merge("slam", slam.Validate());
  check.Merge("control", control.Validate());
  check.Merge("explorer", explorer.Validate());
  check.Merge("render", render.Validate());
  // Control steps are counted in an int: at most 1e8 (about 115 days at
  // 10 Hz); this also refuses an infinite duration.
  if (run.duration_s > 0 && run.control_rate_hz > 0) {
    check.Require(run.duration_s * run.control_rate_hz <= kMaxControlSteps, "run.duration_s",
                  run.duration_s,
                  "at most 1e8 control steps (duration_s * control_rate_hz <= 1e8)");
  }
  // The laser fires on control steps only.
  if (run.control_rate_hz > 0 && laser.rate_hz > 0) {
    const double ratio = run.control_rate_hz / laser.rate_hz;
    check.Require(ratio >= 1.0 - 1e-9 && std::abs(ratio - std::round(ratio)) < 1e-9,
                  "laser.rate_hz", laser.rate_hz,
                  "a rate that divides run.control_rate_hz (" +
                      ValueText(run.control_rate_hz) + ")");
  }
  // The explorer navigates with one filter's pose, the odometry or the truth.
  std::vector<std::string> sources = slam::FilterNamesOf(slam);
  sources.insert(sources.end(), {"odometry", "ground_truth"});
  check.OneOf("control.pose_source", control.pose_source, sources);
  // The filters predict the point h that the robot is driven by.
  check.Require(slam.ekf.control_point_offset_m == robot.control_point_offset_m,
                "slam.ekf.control_point_offset_m", slam.ekf.control_point_offset_m,
                "robot.control_point_offset_m (" + ValueText(robot.control_point_offset_m) +
                    "): the filters must predict the robot's point h");
  // The odometry's wheel models need the robot's track.
  check.Require(slam.ekf.axle_track_m == robot.axle_track_m, "slam.ekf.axle_track_m",
                slam.ekf.axle_track_m,
                "robot.axle_track_m (" + ValueText(robot.axle_track_m) +
                    "): the filters split the odometry into the robot's wheels");
  return check.problems();
}

int RunConfig::StepsPerScan() const {
  return static_cast<int>(std::lround(run.control_rate_hz / laser.rate_hz));
}

namespace {

// Makes `path` absolute against `base` when it is relative.
std::string Absolute(const std::string& path, const std::filesystem::path& base) {
  std::filesystem::path p(path);
  if (p.is_relative()) p = base / p;
  return p.lexically_normal().string();
}

// The folder a relative path of `key` is relative to: the working folder for
// a `--set` option, else the folder of the config file that set it (a base
// file's paths are relative to the base).
std::filesystem::path FolderOf(const config::internal::MarkTable& marks, const std::string& key,
                               const std::string& path) {
  const std::string source = marks.Find(key, path).source;
  if (source.rfind("--set ", 0) == 0) return std::filesystem::current_path();
  return std::filesystem::absolute(std::filesystem::path(source)).parent_path();
}

}  // namespace

RunConfig LoadRunConfig(const std::string& path, const std::vector<std::string>& overrides) {
  config::internal::MarkTable marks;
  RunConfig config = config::LoadConfigFile<RunConfig>(path, overrides, &marks);
  config.run.world = Absolute(config.run.world, FolderOf(marks, "run.world", path));
  config.run.robot_model =
      Absolute(config.run.robot_model, FolderOf(marks, "run.robot_model", path));
  return config;
}

}  // namespace mjslam::app
