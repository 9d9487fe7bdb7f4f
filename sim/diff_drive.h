#pragma once

#include "common/pose2.h"
#include "common/records.h"
#include "sim/sim_params.h"

namespace mjslam::sim {

/// Speeds of the two drive wheels, rad/s; positive rolls the robot forward.
struct WheelSpeeds {
  double left_radps = 0.0;
  double right_radps = 0.0;
};

/// Wheel speeds for a command (v, w) of frame R. Frame R (the point h) is
/// rigidly attached to the axle, so its yaw rate is the axle's and `v` is the
/// axle centre's speed along the heading (the paper's u in Eq. (6)):
///
///     w_l = (v - w L / 2) / r,   w_r = (v + w L / 2) / r
///
/// with L = axle_track_m and r = wheel_radius_m. No saturation.
WheelSpeeds WheelSpeedsFromTwist(const Twist2& command, const RobotParams& robot);

/// Inverse of WheelSpeedsFromTwist: v = r (w_r + w_l) / 2, w = r (w_r - w_l) / L.
Twist2 TwistFromWheelSpeeds(const WheelSpeeds& wheels, const RobotParams& robot);

/// Scales (v, w) by one factor in (0, 1] so that |v| <= max_linear_speed_mps,
/// |w| <= max_angular_speed_radps and both wheel speeds are within
/// max_wheel_speed_radps. One common factor keeps the ratio w / v, i.e. the
/// curvature of the path (and the direction of turning in place).
/// The command must be finite (checked).
Twist2 SaturateTwist(const Twist2& command, const RobotParams& robot);

/// Exact motion of frame R under a constant command for `dt_s` seconds: the
/// axle centre follows an arc of curvature w / v, and the point h, `a_m` ahead
/// of it, moves as in the paper's Eq. (6):
///     x' = v cos th - a w sin th,  y' = v sin th + a w cos th,  th' = w.
/// Returns the new X_WR.
Pose2 MoveControlPoint(const Pose2& X_WR, const Twist2& command, double dt_s,
                       double a_m);

}  // namespace mjslam::sim
