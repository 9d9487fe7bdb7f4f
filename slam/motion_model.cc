#include "slam/motion_model.h"

#include <cmath>

#include "common/angles.h"
#include "slam/fast_wrap.h"

namespace mjslam::slam {

Eigen::Vector3d PredictPose(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& increment,
                            double a_m, Eigen::Matrix3d* A, Eigen::Matrix<double, 3, 2>* W) {
  const double c = std::cos(pose_WR.z());
  const double s = std::sin(pose_WR.z());
  const double d = increment.x();
  const double dth = increment.y();

  // Eq. (6): the velocity of h is (u, a w) in R, integrated with the heading
  // at the start of the period (forward Euler, as in the paper).
  const Eigen::Vector3d predicted(pose_WR.x() + d * c - a_m * dth * s,
                                  pose_WR.y() + d * s + a_m * dth * c,
                                  WrapAngleFast(pose_WR.z() + dth));
  if (A != nullptr) {
    A->setIdentity();
    (*A)(0, 2) = -d * s - a_m * dth * c;
    (*A)(1, 2) = d * c - a_m * dth * s;
  }
  if (W != nullptr) {
    *W << c, -a_m * s,
          s, a_m * c,
          0.0, 1.0;
  }
  return predicted;
}

MotionInput CommandInput(const Twist2& command, double dt_s, const CommandNoiseParams& noise) {
  MotionInput input;
  input.increment = Eigen::Vector2d(command.v_mps * dt_s, command.w_radps * dt_s);
  const double sigma_v = noise.v_noise_std_mps + noise.v_noise_fraction * std::abs(command.v_mps);
  const double sigma_w =
      noise.w_noise_std_radps + noise.w_noise_fraction * std::abs(command.w_radps);
  input.covariance = Eigen::Vector2d(dt_s * dt_s * sigma_v * sigma_v,
                                     dt_s * dt_s * sigma_w * sigma_w)
                         .asDiagonal();
  return input;
}

MotionInput OdometryInput(const Pose2& X_OR_previous, const Pose2& X_OR,
                          const OdometryNoiseParams& noise) {
  // The motion of R between the two records, in the previous R frame.
  const Pose2 X_R0R1 = X_OR_previous.Inverse() * X_OR;
  MotionInput input;
  input.increment = Eigen::Vector2d(X_R0R1.x, X_R0R1.theta);
  const double distance = std::abs(X_R0R1.x);
  const double turn = std::abs(X_R0R1.theta);
  // Random-walk slip: variances linear in the distance rolled and the angle turned.
  const double variance_d =
      noise.distance_noise_std_m * noise.distance_noise_std_m +
      noise.distance_noise_std_m_per_sqrt_m * noise.distance_noise_std_m_per_sqrt_m * distance;
  const double variance_th =
      noise.heading_noise_std_rad * noise.heading_noise_std_rad +
      noise.heading_noise_std_rad_per_sqrt_m * noise.heading_noise_std_rad_per_sqrt_m * distance +
      noise.heading_noise_std_rad_per_sqrt_rad * noise.heading_noise_std_rad_per_sqrt_rad * turn;
  input.covariance = Eigen::Vector2d(variance_d, variance_th).asDiagonal();
  return input;
}

}  // namespace mjslam::slam
