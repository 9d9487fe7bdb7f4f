#pragma once

#include <cmath>

#include <Eigen/Core>

#include "common/angles.h"

namespace mjslam {

/// A rigid transform in the plane, in monogram notation: `X_AB` is the pose of
/// frame B measured in frame A. Translation in metres, heading in radians,
/// kept wrapped to (-pi, pi].
struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;

  Pose2() = default;
  Pose2(double x_m, double y_m, double theta_rad)
      : x(x_m), y(y_m), theta(WrapAngle(theta_rad)) {}

  /// Translation p_AB as a vector.
  Eigen::Vector2d translation() const { return {x, y}; }

  /// Composition: X_AC = X_AB * X_BC.
  Pose2 operator*(const Pose2& X_BC) const {
    const double c = std::cos(theta);
    const double s = std::sin(theta);
    return Pose2(x + c * X_BC.x - s * X_BC.y, y + s * X_BC.x + c * X_BC.y,
                 theta + X_BC.theta);
  }

  /// Inverse: X_BA from X_AB.
  Pose2 Inverse() const {
    const double c = std::cos(theta);
    const double s = std::sin(theta);
    return Pose2(-c * x - s * y, s * x - c * y, -theta);
  }

  /// Maps a point from frame B to frame A: p_AP = X_AB * p_BP.
  Eigen::Vector2d operator*(const Eigen::Vector2d& p_BP) const {
    const double c = std::cos(theta);
    const double s = std::sin(theta);
    return {x + c * p_BP.x() - s * p_BP.y(), y + s * p_BP.x() + c * p_BP.y()};
  }
};

}  // namespace mjslam
