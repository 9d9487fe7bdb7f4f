#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/laser_scan.h"
#include "common/pose2.h"
#include "common/records.h"
#include "sim/laser_footprint.h"
#include "sim/mujoco_errors.h"
#include "sim/scene.h"
#include "sim/sim_params.h"

namespace mjslam::sim {

/// The Pioneer 3-DX stepped by MuJoCo in a Scene (the physics on top of the
/// scene: MuJoCo's mjData, the wheel-speed controllers, the clock).
///
/// Frames: W the world; A the axle centre (the robot body's origin); R the
/// point of control h, RobotParams::control_point_offset_m ahead of A on the
/// centre line (the frame of every pose output); S the laser frame, given by
/// the model's `laser` site. All poses are planar (x, y, yaw about z).
class Simulator {
 public:
  /// Puts the physics on `scene` (sharing its loaded model; the simulator's
  /// own copy carries SimParams::timestep_s), places frame R at `X_WR_start`
  /// (default: scene.StartPose()), and lets the robot settle on the floor for
  /// SimParams::settle_time_s; time_s() is then 0. Throws ParamError for
  /// invalid params; SimError when the robot model disagrees with `robot`
  /// (wheel radius or axle track by more than 1 mm), the wheel-speed gain is
  /// unstable at the timestep, the start pose touches an obstacle, the robot
  /// does not come to rest, or MuJoCo raises an error or a warning.
  Simulator(Scene scene, const SimParams& sim, const RobotParams& robot,
            std::optional<Pose2> X_WR_start = std::nullopt);
  /// Validates the params, loads Scene(world_path, robot_model_path) (which
  /// throws SimError for a bad file or a world that breaks the rules), and
  /// puts the physics on it as above.
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

  /// Disturbs the drive: from now on the wheel-speed set points are those of
  /// (v v_factor, w w_factor) for the command (v, w) applied (this one and
  /// the next ones, until the next call); command() stays the undisturbed
  /// command. Factors 1 (the initial ones) leave the set points exact. The
  /// closed loop draws the factors at every control step from
  /// SimParams::drive_disturbance_std_fraction. Both must be finite (checked).
  void SetDriveFactors(double v_factor, double w_factor);

  /// Disturbs the drive wheel by wheel: from now on each wheel's speed set
  /// point is scaled by its factor (after those of SetDriveFactors), until
  /// the next call. Factors 1 (the initial ones) leave the set points exact;
  /// the closed loop draws them with SimParams::drive_disturbance "wheels".
  /// Both must be finite (checked).
  void SetWheelFactors(double left_factor, double right_factor);

  /// Advances the physics by whole timesteps: after the call the simulated
  /// time is the multiple of the timestep nearest to the sum of all durations
  /// requested so far (so ten Advance(0.1) make exactly 1 s). Throws SimError
  /// on any MuJoCo error or warning (instability, bad numbers, full contact
  /// buffer) or if the robot leaves the floor (tips over, is launched); the
  /// simulator must then be discarded. duration_s must be >= 0 (throws
  /// SimError).
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
  /// `laser`, SimError for a wrong number of offsets or a MuJoCo error. Cast
  /// only at the scan rate: it costs num_beams ray casts.
  /// `footprint` (optional): filled with what the laser's error structure
  /// needs (sim/laser_footprint.h): footprint_rays more casts per beam with
  /// mixed pixels on, two more with grazing dropouts on; the scan itself is
  /// the same with or without it.
  LaserScan CastLaser(const LaserParams& laser,
                      const std::vector<double>& beam_angle_offsets_rad = {},
                      LaserFootprint* footprint = nullptr) const;

  /// Whether contacts and laser beams consider only the world geoms that
  /// matter (true, the default) or every geom (false: MuJoCo's all-pairs
  /// collision and mj_ray, as MuJoCo alone does; for checks and benchmarks).
  /// Either way the results are the same, bit for bit: with it on, the
  /// static world geoms farther than the robot can reach before the next
  /// refresh do not collide (their contype and conaffinity are 0 in the
  /// simulator's model copy), and each beam tests, with mj_ray's own per-geom
  /// functions, only the static geoms listed in the cells of a 1 m grid that
  /// it crosses, up to its first hit (sim/README.md, "Local contacts and
  /// beams"). Can be switched at any time.
  void SetLocalWorldGeoms(bool on);
  bool local_world_geoms() const;
  /// Whether the physics now steps the local model (sim/README.md, "The
  /// local physics model"): the robot and, in a pool of slots, only the
  /// world geoms it can touch before the next refresh, with the same
  /// contacts in the same order as the full scene, so the same physics bit
  /// for bit at a cost that does not grow with the world. True while
  /// local_world_geoms() unless local_model_problem() is not empty; then the
  /// full scene is stepped with the far geoms' contacts switched off.
  bool steps_local_model() const;
  /// Why this world cannot have a local model (empty when it can): a
  /// colliding static geom that is a mesh or height field or not on the
  /// world body, explicit <pair> or <exclude>, or a robot that compiles
  /// differently with the world than alone.
  const std::string& local_model_problem() const;

  /// Number of contacts between robot geoms and world geoms other than
  /// planes (the floor): 0 unless the robot touches an obstacle.
  int CountRobotWorldContacts() const;

  /// The scene the physics runs on (start, tour, obstacles, files).
  const Scene& scene() const;
  /// The robot parameters in use.
  const RobotParams& robot() const;
  /// The composed model's generalized positions (free joint x y z qw qx qy qz,
  /// then the left and right wheel angles), e.g. to draw the same state in
  /// another copy of the scene's model (renders::SceneRenderer).
  std::vector<double> QPos() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mjslam::sim
