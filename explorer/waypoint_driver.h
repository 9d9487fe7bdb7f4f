#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "common/params.h"
#include "common/pose2.h"
#include "common/records.h"

namespace mjslam::explorer {

/// The built-in driver that steers the point h through a list of waypoints
/// until the frontier explorer takes over. Serialized under `driver.*`.
struct WaypointDriverParams {
  /// Waypoints (x, y) in the world frame, metres. Empty: follow the world's
  /// tour (its `tour_0`, `tour_1`, ... sites).
  std::vector<std::array<double, 2>> waypoints;
  /// Start over at the first waypoint after the last one.
  bool loop = true;
  /// Speed of h along the way, m/s.
  double cruise_speed_mps = 0.4;
  /// Limits of the commands, m/s and rad/s (below the motor limits).
  double max_linear_speed_mps = 0.6;
  double max_angular_speed_radps = 1.2;
  /// Acceleration limits of the commands, m/s^2 and rad/s^2.
  double max_linear_accel_mps2 = 0.5;
  double max_angular_accel_radps2 = 2.0;
  /// A waypoint counts as reached when h is this close, metres.
  double waypoint_tolerance_m = 0.3;
  /// Bearing error above which the robot turns in place first, degrees.
  double turn_in_place_deg = 60.0;
  /// Gain of the in-place turn: w = gain * bearing error, 1/s.
  double turn_gain_per_s = 1.5;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(waypoints));
    a->Visit(MJSLAM_NVP(loop));
    a->Visit(MJSLAM_NVP(cruise_speed_mps));
    a->Visit(MJSLAM_NVP(max_linear_speed_mps));
    a->Visit(MJSLAM_NVP(max_angular_speed_radps));
    a->Visit(MJSLAM_NVP(max_linear_accel_mps2));
    a->Visit(MJSLAM_NVP(max_angular_accel_radps2));
    a->Visit(MJSLAM_NVP(waypoint_tolerance_m));
    a->Visit(MJSLAM_NVP(turn_in_place_deg));
    a->Visit(MJSLAM_NVP(turn_gain_per_s));
  }
  std::vector<ParamProblem> Validate() const;
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }
};

/// Steers frame R (the point h, `a` ahead of the axle) through waypoints:
/// turns in place toward a waypoint that lies far off the heading, otherwise
/// drives h straight at it through the inverted kinematics of h
/// (CommandForPointVelocity), with speed and acceleration limits.
class WaypointDriver {
 public:
  /// `waypoints` in the world frame (at least one); `a_m` > 0 is the offset of
  /// h. Throws ParamError on invalid params or an empty waypoint list.
  WaypointDriver(const WaypointDriverParams& params,
                 std::vector<Eigen::Vector2d> waypoints, double a_m);

  /// The command for the next `dt_s` seconds given the pose of R.
  Twist2 Command(const Pose2& X_WR, double dt_s);

  /// True once the last waypoint was reached (never when looping).
  bool finished() const { return finished_; }
  /// Index of the waypoint being approached.
  int target_index() const { return target_; }

 private:
  WaypointDriverParams params_;
  std::vector<Eigen::Vector2d> waypoints_;
  double a_m_;
  int target_ = 0;
  bool finished_ = false;
  Twist2 last_;
};

}  // namespace mjslam::explorer
