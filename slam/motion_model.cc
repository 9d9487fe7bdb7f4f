#include "slam/motion_model.h"

#include <cmath>

#include "common/angles.h"
#include "slam/fast_wrap.h"

namespace mjslam::slam {
namespace {

// The paper's forward-Euler Eq. (6) over one step, with the heading th at the
// start of the period, plus the skid across that heading; A and W as in
// PredictPose.
Eigen::Vector3d PredictPoseEuler(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& increment,
                                 double a_m, Eigen::Matrix3d* A, Eigen::Matrix<double, 3, 2>* W,
                                 double skid_per_m_rad) {
  const double d = increment.x();
  const double dth = increment.y();
  const double c = std::cos(pose_WR.z());
  const double s = std::sin(pose_WR.z());
  // Sideways: a dth for the point h ahead of the axle, and the skid outward.
  const double lateral = a_m * dth - skid_per_m_rad * d * dth;
  const double dx = d * c - lateral * s;
  const double dy = d * s + lateral * c;
  const Eigen::Vector3d predicted(pose_WR.x() + dx, pose_WR.y() + dy,
                                  WrapAngleFast(pose_WR.z() + dth));
  if (A != nullptr) {
    A->setIdentity();
    (*A)(0, 2) = -dy;
    (*A)(1, 2) = dx;
  }
  if (W != nullptr) {
    const double dlat_dd = -skid_per_m_rad * dth;
    const double dlat_dth = a_m - skid_per_m_rad * d;
    *W << c - dlat_dd * s, -dlat_dth * s,
          s + dlat_dd * c, dlat_dth * c,
          0.0, 1.0;
  }
  return predicted;
}

}  // namespace

Eigen::Vector3d PredictPose(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& increment,
                            double a_m, Eigen::Matrix3d* A, Eigen::Matrix<double, 3, 2>* W,
                            double skid_per_m_rad, MotionIntegration integration) {
  if (integration == MotionIntegration::kEuler) {
    return PredictPoseEuler(pose_WR, increment, a_m, A, W, skid_per_m_rad);
  }
  const double d = increment.x();
  const double dth = increment.y();
  const double half = 0.5 * dth;
  const double th_mid = pose_WR.z() + half;
  const double cm = std::cos(th_mid);
  const double sm = std::sin(th_mid);
  // sinc(half) and its derivative with respect to dth.
  double sinc, dsinc;
  if (std::abs(half) < 1e-4) {
    sinc = 1.0 - half * half / 6.0;
    dsinc = -half / 6.0;
  } else {
    sinc = std::sin(half) / half;
    dsinc = 0.5 * (half * std::cos(half) - std::sin(half)) / (half * half);
  }
  const double chord = d * sinc;
  // Sideways: the point h swinging about the axle, and the skid outward.
  const double lateral = 2.0 * a_m * std::sin(half) - skid_per_m_rad * d * dth;
  const double dx = chord * cm - lateral * sm;
  const double dy = chord * sm + lateral * cm;
  const Eigen::Vector3d predicted(pose_WR.x() + dx, pose_WR.y() + dy,
                                  WrapAngleFast(pose_WR.z() + dth));
  if (A != nullptr) {
    A->setIdentity();
    (*A)(0, 2) = -dy;
    (*A)(1, 2) = dx;
  }
  if (W != nullptr) {
    const double dlat_dd = -skid_per_m_rad * dth;
    const double dlat_dth = a_m * std::cos(half) - skid_per_m_rad * d;
    *W << sinc * cm - dlat_dd * sm, d * dsinc * cm - dlat_dth * sm - 0.5 * dy,
          sinc * sm + dlat_dd * cm, d * dsinc * sm + dlat_dth * cm + 0.5 * dx,
          0.0, 1.0;
  }
  return predicted;
}

MotionInput CommandInput(const Twist2& command, double dt_s, const CommandNoiseParams& noise,
                         const Twist2& previous) {
  MotionInput input;
  input.increment = Eigen::Vector2d(command.v_mps * dt_s, command.w_radps * dt_s);
  const double sigma_v = noise.v_noise_std_mps + noise.v_noise_fraction * std::abs(command.v_mps) +
                         noise.change_noise_fraction * std::abs(command.v_mps - previous.v_mps);
  const double sigma_w =
      noise.w_noise_std_radps + noise.w_noise_fraction * std::abs(command.w_radps) +
      noise.change_noise_fraction * std::abs(command.w_radps - previous.w_radps);
  input.covariance = Eigen::Vector2d(dt_s * dt_s * sigma_v * sigma_v,
                                     dt_s * dt_s * sigma_w * sigma_w)
                         .asDiagonal();
  return input;
}

MotionInput OdometryInput(const Pose2& X_OR_previous, const Pose2& X_OR, double a_m,
                          const OdometryNoiseParams& noise) {
  // The motion of R between the two records, in the previous R frame, and
  // that of the axle centre (a_m behind R): a chord of the arc, at half the
  // heading change.
  const Pose2 X_R0R1 = X_OR_previous.Inverse() * X_OR;
  const double dth = X_R0R1.theta;
  const double half = 0.5 * dth;
  const double axle_dx = X_R0R1.x - a_m * (std::cos(dth) - 1.0);
  const double axle_dy = X_R0R1.y - a_m * std::sin(dth);
  const double chord = axle_dx * std::cos(half) + axle_dy * std::sin(half);
  const double sinc = std::abs(half) < 1e-4 ? 1.0 - half * half / 6.0 : std::sin(half) / half;
  MotionInput input;
  input.increment = Eigen::Vector2d(chord / sinc, dth);
  const double distance = std::abs(input.increment.x());
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
