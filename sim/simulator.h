#pragma once

#include <array>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/laser_scan.h"
#include "common/pose2.h"
#include "common/records.h"
#include "sim/obstacles.h"
#include "sim/sim_params.h"

namespace mjslam::sim {

/// A problem with the simulation's input (world or robot file, start pose) or
/// a physics failure (a MuJoCo error or warning). The message names the file
/// and carries MuJoCo's own text.
class SimError : public std::runtime_error {
 public:
  explicit SimError(const std::string& message) : std::runtime_error(message) {}
};

/// Points MuJoCo's process-wide error and warning hooks (mju_user_error,
/// mju_user_warning), where they are still unset, at handlers that throw
/// SimError("MuJoCo error: ...") / SimError("MuJoCo warning: ..."). MuJoCo's
/// defaults wait for a key press and exit (errors) or write MUJOCO_LOG.TXT
/// (warnings). The Simulator calls this; a program or test that installs its
/// own hooks first keeps them (they must not return: throw). After an error
/// thrown from inside MuJoCo, the Simulator that was running is in an
/// undefined state and must be discarded.
void InstallMujocoErrorHandlers();

/// MuJoCo's version string (for run manifests), e.g. "2.2.2".
std::string MujocoVersion();

/// The Pioneer 3-DX in a world, stepped by MuJoCo.
///
/// The world file is an MJCF file with a floor plane, static obstacle geoms, a
/// site `start` (the default start pose of R: its x, y and yaw) and optionally
/// sites `tour_0`, `tour_1`, ... (see worlds/README.md). The robot file is the
/// robot's MJCF (models/pioneer3dx.xml; its required names are listed in
/// models/README.md). The two are composed into one model by a wrapper that
/// includes both, so any world file works without edits.
///
/// Frames: W the world; A the axle centre (the robot body's origin); R the
/// point of control h, RobotParams::control_point_offset_m ahead of A on the
/// centre line (the frame of every pose output); S the laser frame, given by
/// the model's `laser` site. All poses are planar (x, y, yaw about z).
class Simulator {
 public:
  /// Loads and composes the world and robot files, checks them, places frame
  /// R at `X_WR_start` (default: the world's `start` site), and lets the robot
  /// settle on the floor for SimParams::settle_time_s; time_s() is then 0.
  /// Throws SimError (naming the file and quoting MuJoCo's message) when a
  /// file is missing or malformed, the world lacks the `start` site, uses
  /// geom group 5 (reserved for the robot), has joints of its own, has
  /// misnumbered tour sites, the robot model lacks a required name or
  /// disagrees with `robot` (wheel radius or axle track by more than 1 mm),
  /// the wheel-speed gain is unstable at the timestep, the start pose touches
  /// an obstacle, or the robot does not come to rest. Throws ParamError for
  /// invalid params.
  Simulator(const std::string& world_path, const std::string& robot_model_path,
            const SimParams& sim, const RobotParams& robot,
            std::optional<Pose2> X_WR_start = std::nullopt);
  ~Simulator();
  Simulator(Simulator&&) noexcept;
  Simulator& operator=(Simulator&&) noexcept;
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  /// Sets the command (v, w) of frame R (v: the axle centre's speed along the
  /// heading, m/s; w: yaw rate, rad/s; see sim/diff_drive.h), held until the
  /// next call. It is saturated by SaturateTwist (one common factor, so the
  /// curvature is kept) and turned into the set points of the wheel-speed
  /// controllers (see SimParams). Returns the saturated command actually
  /// applied. The command must be finite (checked).
  Twist2 SetCommand(const Twist2& command);

  /// The saturated command currently applied.
  Twist2 command() const;

  /// Advances the physics by whole timesteps: after the call the simulated
  /// time is the multiple of the timestep nearest to the sum of all durations
  /// requested so far (so ten Advance(0.1) make exactly 1 s). Throws SimError
  /// on any MuJoCo warning (instability, bad numbers, full contact buffer) or
  /// if the robot leaves the floor (tips over, is launched); the simulator
  /// must then be discarded. duration_s must be >= 0 (throws SimError).
  void Advance(double duration_s);

  /// Simulated time since the start of the run, seconds.
  double time_s() const;
  /// Physics timestep, seconds.
  double timestep_s() const;

  /// True pose of frame R (the point h) in the world.
  Pose2 X_WR() const;
  /// Pose of the laser frame S in R (constant, from the model).
  Pose2 X_RS() const;
  /// True pose of the laser frame S in the world: X_WR() * X_RS().
  Pose2 X_WS() const;
  /// True velocity of R as a command would express it: the axle centre's
  /// speed along the heading (m/s) and the yaw rate (rad/s).
  Twist2 TrueTwist() const;

  /// Drive wheel hinge angles {left, right}, radians, forward rotation
  /// positive, unwrapped (the encoders' input, see sim/wheel_odometry.h).
  std::array<double, 2> WheelAngles() const;
  /// Drive wheel angular velocities {left, right}, rad/s (forward positive).
  std::array<double, 2> WheelVelocities() const;

  /// One exact sweep from the `laser` site at the current state: beam i at
  /// bearing laser.AngleMinRad() + i * laser.AngleIncrementRad() in S, cast
  /// with mj_ray in the horizontal plane of S at the site's height, against
  /// every world geom except those in group 5 (the robot) and those with
  /// rgba alpha 0 (mj_ray skips invisible geoms). A beam with no surface
  /// within max_range_m has range max_range_m and has_return 0.
  /// `beam_angle_offsets_rad` (empty, or one per beam): beam i is really cast
  /// at its bearing plus offset i (angular jitter, see LaserNoise) but the
  /// scan reports the nominal bearings. Throws ParamError for invalid
  /// `laser`, SimError for a wrong number of offsets. Cast only at the scan
  /// rate: it costs num_beams ray casts.
  LaserScan CastLaser(const LaserParams& laser,
                      const std::vector<double>& beam_angle_offsets_rad = {}) const;

  /// The world's sites tour_0, tour_1, ... in order: waypoints p_W for the
  /// point h (x, y). Empty if the world has none.
  std::vector<Eigen::Vector2d> TourWaypoints() const;
  /// The world's `start` site as a pose of R (x, y, yaw).
  Pose2 StartPose() const;
  /// Number of contacts between robot geoms and world geoms other than
  /// planes (the floor): 0 unless the robot touches an obstacle.
  int CountRobotWorldContacts() const;
  /// Footprints of the world's obstacle geoms (everything but planes, height
  /// fields and the robot), in the order of the model: the ground-truth map.
  std::vector<ObstacleFootprint> Obstacles() const;

  /// The robot parameters in use.
  const RobotParams& robot() const;
  /// Absolute paths of the loaded files.
  const std::string& world_path() const;
  const std::string& robot_model_path() const;
  /// The composed model's generalized positions (free joint x y z qw qx qy qz,
  /// then the left and right wheel angles), e.g. to draw the same state in a
  /// separately loaded copy of the scene (see SceneXml()).
  std::vector<double> QPos() const;
  /// The wrapper MJCF that composes the scene; it must be loaded from a file
  /// in the world file's directory (its includes are relative to it).
  const std::string& SceneXml() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mjslam::sim
