#include "explorer/waypoint_driver.h"

#include <algorithm>
#include <cmath>

#include "common/angles.h"
#include "explorer/point_h_controller.h"

namespace mjslam::explorer {

std::vector<ParamProblem> WaypointDriverParams::Validate() const {
  ParamChecker check;
  check.Positive("cruise_speed_mps", cruise_speed_mps);
  check.Positive("max_linear_speed_mps", max_linear_speed_mps);
  check.Positive("max_angular_speed_radps", max_angular_speed_radps);
  check.Positive("max_linear_accel_mps2", max_linear_accel_mps2);
  check.Positive("max_angular_accel_radps2", max_angular_accel_radps2);
  check.Positive("waypoint_tolerance_m", waypoint_tolerance_m);
  check.InRange("turn_in_place_deg", turn_in_place_deg, 1.0, 180.0);
  check.Positive("turn_gain_per_s", turn_gain_per_s);
  check.Require(cruise_speed_mps <= max_linear_speed_mps, "cruise_speed_mps",
                cruise_speed_mps, "at most max_linear_speed_mps");
  return check.problems();
}

WaypointDriver::WaypointDriver(const WaypointDriverParams& params,
                               std::vector<Eigen::Vector2d> waypoints, double a_m)
    : params_(params), waypoints_(std::move(waypoints)), a_m_(a_m) {
  params_.ValidateOrThrow();
  if (waypoints_.empty()) {
    throw ParamError("driver.waypoints: expected at least one waypoint (got none, "
                     "and the world has no tour_0 site)");
  }
  if (!(a_m_ > 0.0)) {
    throw ParamError("robot.control_point_offset_m: expected a value > 0 (got " +
                     ValueText(a_m_) + ")");
  }
}

Twist2 WaypointDriver::Command(const Pose2& X_WR, double dt_s) {
  const Eigen::Vector2d p_WR = X_WR.translation();

  // Advance past every waypoint that h has reached.
  while (!finished_ && (waypoints_[target_] - p_WR).norm() < params_.waypoint_tolerance_m) {
    if (target_ + 1 < static_cast<int>(waypoints_.size())) {
      ++target_;
    } else if (params_.loop) {
      target_ = 0;
    } else {
      finished_ = true;
    }
  }

  Twist2 desired;
  if (!finished_) {
    const Eigen::Vector2d to_target = waypoints_[target_] - p_WR;
    const double bearing_error =
        WrapAngle(std::atan2(to_target.y(), to_target.x()) - X_WR.theta);
    if (std::abs(bearing_error) > DegToRad(params_.turn_in_place_deg)) {
      // Far off the heading: turn toward the waypoint first.
      desired.w_radps = params_.turn_gain_per_s * bearing_error;
    } else {
      // Drive h straight at the waypoint, slowing down for the last one.
      double speed = params_.cruise_speed_mps;
      const bool last = !params_.loop && target_ + 1 == static_cast<int>(waypoints_.size());
      if (last) speed = std::min(speed, to_target.norm());
      desired = CommandForPointVelocity(X_WR, speed * to_target.normalized(), a_m_);
    }
  }
  desired = SaturateKeepingCurvature(desired, params_.max_linear_speed_mps,
                                     params_.max_angular_speed_radps);
  last_ = RateLimit(last_, desired, params_.max_linear_accel_mps2 * dt_s,
                    params_.max_angular_accel_radps2 * dt_s);
  return last_;
}

}  // namespace mjslam::explorer
