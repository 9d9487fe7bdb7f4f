#include "sim/diff_drive.h"

#include <algorithm>
#include <cmath>

#include "common/check.h"

namespace mjslam::sim {

WheelSpeeds WheelSpeedsFromTwist(const Twist2& command, const RobotParams& robot) {
  const double half_track = 0.5 * robot.axle_track_m;
  WheelSpeeds wheels;
  wheels.left_radps = (command.v_mps - command.w_radps * half_track) / robot.wheel_radius_m;
  wheels.right_radps = (command.v_mps + command.w_radps * half_track) / robot.wheel_radius_m;
  return wheels;
}

Twist2 TwistFromWheelSpeeds(const WheelSpeeds& wheels, const RobotParams& robot) {
  Twist2 twist;
  twist.v_mps = 0.5 * robot.wheel_radius_m * (wheels.right_radps + wheels.left_radps);
  twist.w_radps =
      robot.wheel_radius_m * (wheels.right_radps - wheels.left_radps) / robot.axle_track_m;
  return twist;
}

Twist2 SaturateTwist(const Twist2& command, const RobotParams& robot) {
  MJSLAM_CHECK(std::isfinite(command.v_mps) && std::isfinite(command.w_radps));
  // The largest common factor that satisfies each limit.
  double scale = 1.0;
  const auto limit = [&scale](double value, double max_value) {
    if (std::abs(value) > max_value) scale = std::min(scale, max_value / std::abs(value));
  };
  limit(command.v_mps, robot.max_linear_speed_mps);
  limit(command.w_radps, robot.max_angular_speed_radps);
  const WheelSpeeds wheels = WheelSpeedsFromTwist(command, robot);
  limit(wheels.left_radps, robot.max_wheel_speed_radps);
  limit(wheels.right_radps, robot.max_wheel_speed_radps);
  return Twist2{scale * command.v_mps, scale * command.w_radps};
}

Pose2 MoveControlPoint(const Pose2& X_WR, const Twist2& command, double dt_s,
                       double a_m) {
  // Axle centre A, a behind h on the centre line.
  const Pose2 X_WA = X_WR * Pose2(-a_m, 0.0, 0.0);
  const double v = command.v_mps;
  const double w = command.w_radps;
  const double th0 = X_WA.theta;
  const double th1 = th0 + w * dt_s;
  // The axle follows an arc (a straight line when w is ~0).
  double dx = 0.0;
  double dy = 0.0;
  if (std::abs(w * dt_s) < 1e-9) {
    const double th_mid = th0 + 0.5 * w * dt_s;
    dx = v * dt_s * std::cos(th_mid);
    dy = v * dt_s * std::sin(th_mid);
  } else {
    dx = v / w * (std::sin(th1) - std::sin(th0));
    dy = -v / w * (std::cos(th1) - std::cos(th0));
  }
  const Pose2 X_WA_new(X_WA.x + dx, X_WA.y + dy, th1);
  return X_WA_new * Pose2(a_m, 0.0, 0.0);
}

}  // namespace mjslam::sim
