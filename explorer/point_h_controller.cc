#include "explorer/point_h_controller.h"

#include <algorithm>
#include <cmath>

#include "common/check.h"

namespace mjslam::explorer {

Twist2 CommandForPointVelocity(const Pose2& X_WR, const Eigen::Vector2d& v_W_desired,
                               double a_m) {
  MJSLAM_CHECK(a_m > 0.0);
  const double c = std::cos(X_WR.theta);
  const double s = std::sin(X_WR.theta);
  // J^-1 = [ c      s   ]
  //        [-s/a   c/a  ]
  Twist2 command;
  command.v_mps = c * v_W_desired.x() + s * v_W_desired.y();
  command.w_radps = (-s * v_W_desired.x() + c * v_W_desired.y()) / a_m;
  return command;
}

Twist2 SaturateKeepingCurvature(const Twist2& command, double max_v_mps,
                                double max_w_radps) {
  double scale = 1.0;
  if (std::abs(command.v_mps) > max_v_mps) scale = max_v_mps / std::abs(command.v_mps);
  if (std::abs(command.w_radps) * scale > max_w_radps) {
    scale = max_w_radps / std::abs(command.w_radps);
  }
  return {command.v_mps * scale, command.w_radps * scale};
}

Twist2 RateLimit(const Twist2& previous, const Twist2& target, double max_dv_mps,
                 double max_dw_radps) {
  Twist2 limited;
  limited.v_mps = previous.v_mps +
                  std::clamp(target.v_mps - previous.v_mps, -max_dv_mps, max_dv_mps);
  limited.w_radps = previous.w_radps + std::clamp(target.w_radps - previous.w_radps,
                                                  -max_dw_radps, max_dw_radps);
  return limited;
}

}  // namespace mjslam::explorer
