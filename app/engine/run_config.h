#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "app/engine/control.h"
#include "common/params.h"
#include "explorer/explorer_params.h"
#include "explorer/waypoint_driver.h"
#include "renders/render_params.h"
#include "sim/sim_params.h"
#include "slam/slam_params.h"

namespace mjslam::app {

/// What to run and for how long. Serialized under `run.*`.
struct RunParams {
  /// Root seed of every random stream of the run.
  std::uint64_t seed = 1;
  /// Simulated time to run, seconds.
  double duration_s = 120.0;
  /// Rate of the control loop (driver, odometry, SLAM records), Hz. The
  /// laser rate must divide it.
  double control_rate_hz = 10.0;
  /// World MJCF file. Relative paths in a config file are relative to the
  /// file's folder; the resolved config holds absolute paths.
  std::string world = "../worlds/corridor_loop.xml";
  /// Robot MJCF file, same path rules as `world`.
  std::string robot_model = "../models/pioneer3dx.xml";

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(seed));
    a->Visit(MJSLAM_NVP(duration_s));
    a->Visit(MJSLAM_NVP(control_rate_hz));
    a->Visit(MJSLAM_NVP(world));
    a->Visit(MJSLAM_NVP(robot_model));
  }
  std::vector<ParamProblem> Validate() const;
};

/// The whole configuration of a run: one YAML file (configs/default.yaml),
/// one section per module.
struct RunConfig {
  RunParams run;
  sim::SimParams sim;
  sim::RobotParams robot;
  sim::LaserParams laser;
  sim::OdometryParams odometry;
  explorer::WaypointDriverParams driver;
  slam::SlamParams slam;
  ControlParams control;
  explorer::ExplorerParams explorer;
  /// Renders at the end of a completed `mjslam run` (renders/).
  renders::RenderParams render;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(run));
    a->Visit(MJSLAM_NVP(sim));
    a->Visit(MJSLAM_NVP(robot));
    a->Visit(MJSLAM_NVP(laser));
    a->Visit(MJSLAM_NVP(odometry));
    a->Visit(MJSLAM_NVP(driver));
    a->Visit(MJSLAM_NVP(slam));
    a->Visit(MJSLAM_NVP(control));
    a->Visit(MJSLAM_NVP(explorer));
    a->Visit(MJSLAM_NVP(render));
  }
  std::vector<ParamProblem> Validate() const;
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }

  /// Number of control steps between two scans.
  int StepsPerScan() const;
};

/// Loads a run config from `path`, applies `--set` overrides, and makes the
/// `run.world` and `run.robot_model` paths absolute (relative to the config
/// file's folder; an override given on the command line is relative to the
/// working directory). Throws config::ConfigError listing every problem.
RunConfig LoadRunConfig(const std::string& path, const std::vector<std::string>& overrides);

}  // namespace mjslam::app
