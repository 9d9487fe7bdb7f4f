#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/pose2.h"
#include "sim/mujoco_errors.h"
#include "sim/obstacles.h"

namespace mjslam::sim {

namespace internal {
class SceneAccess;
}  // namespace internal

/// A world with the Pioneer 3-DX in it, loaded once and checked, without
/// physics: what the evaluation, the renders and the simulator share (model
/// apart from data, as MuJoCo's sample/record.cc). sim::Simulator puts the
/// physics on a Scene; renders::SceneRenderer draws it.
///
/// The world file is an MJCF file with a floor plane, static obstacle geoms, a
/// site `start` (the default start pose of R: its x, y and yaw) and optionally
/// sites `tour_0`, `tour_1`, ... (see worlds/README.md). The robot file is the
/// robot's MJCF (models/pioneer3dx.xml; its required names are listed in
/// models/README.md). The two are composed into one model by a wrapper that
/// includes both, so any world file works without edits.
///
/// Everything a Scene reports is read at load, at the model's reference
/// configuration (static geoms and sites do not move). A Scene is immutable;
/// copies share the loaded model and are cheap.
class Scene {
 public:
  /// Loads and composes the world and robot files and checks the world's
  /// and the robot model's rules. Throws SimError (naming the file and
  /// quoting MuJoCo's message) when a file is missing or malformed, the world
  /// lacks the `start` site, uses geom group 5 (reserved for the robot), has
  /// joints or actuators of its own, has misnumbered tour sites, or the robot
  /// model lacks a required name or a wheel's single colliding geom (a sphere
  /// or a cylinder). Runs no physics step.
  Scene(const std::string& world_path, const std::string& robot_model_path);

  /// The world's `start` site as a pose of R (x, y, yaw), W frame.
  const Pose2& StartPose() const;
  /// The world's sites tour_0, tour_1, ... in order: waypoints p_W for the
  /// point h (x, y). Empty if the world has none.
  const std::vector<Eigen::Vector2d>& TourWaypoints() const;
  /// Footprints of the world's obstacle geoms (everything but planes, height
  /// fields and the robot), in the order of the model: the ground-truth map.
  const std::vector<ObstacleFootprint>& Obstacles() const;

  /// Radii of the robot model's wheels {left, right} (their colliding
  /// geoms), metres.
  const std::array<double, 2>& WheelRadiiM() const;
  /// Distance between the robot model's wheel centres in the floor plane,
  /// metres.
  double AxleTrackM() const;

  /// Absolute paths of the loaded files.
  const std::string& world_path() const;
  const std::string& robot_model_path() const;
  /// "world '<path>' with robot '<path>'", for messages.
  std::string Description() const;

 private:
  friend class internal::SceneAccess;
  struct Impl;
  // Loads the files, composes them and runs the checks; the start, the tour,
  // the obstacles and the wheel geometry are read at the reference
  // configuration (mj_kinematics only: no physics step).
  static std::shared_ptr<const Impl> Load(const std::string& world_path,
                                          const std::string& robot_model_path);
  std::shared_ptr<const Impl> impl_;
};

/// Throws SimError naming the world file, the geom that lies farthest out
/// and the key, when the footprints of the world's obstacles (by their
/// bounding discs) and its start do not fit in an axis-aligned square of
/// side `max_extent_m` (SimParams::max_world_extent_m), or one is not
/// finite. Called before any grid over the world is allocated.
void CheckWorldExtent(const Scene& scene, double max_extent_m);

/// The same check of `obstacles` and `p_W_start` of the world at
/// `world_path` (for messages).
void CheckWorldExtent(const std::string& world_path, const Eigen::Vector2d& p_W_start,
                      const std::vector<ObstacleFootprint>& obstacles, double max_extent_m);

}  // namespace mjslam::sim
