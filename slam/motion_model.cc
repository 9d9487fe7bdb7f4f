#include "slam/motion_model.h"

#include <algorithm>
#include <cmath>

#include "common/angles.h"
#include "slam/fast_wrap.h"

namespace mjslam::slam {
namespace {

// One step of R: `forward` along the heading `phi` and `lateral` across it,
// with their derivatives by the increment (d, dth); the heading turns by dth.
struct PlanarStep {
  double phi = 0.0;
  double dphi_ddth = 0.0;
  double forward = 0.0;
  double dforward_dd = 0.0;
  double dforward_ddth = 0.0;
  double lateral = 0.0;
  double dlateral_dd = 0.0;
  double dlateral_ddth = 0.0;
};

// The pose after `step` from `pose_WR` turning by `dth`, and if not null its
// Jacobians A = d pose' / d pose and W = d pose' / d (d, dth).
Eigen::Vector3d ApplyStep(const Eigen::Vector3d& pose_WR, double dth, const PlanarStep& step,
                          Eigen::Matrix3d* A, Eigen::Matrix<double, 3, 2>* W) {
  const double cm = std::cos(step.phi);
  const double sm = std::sin(step.phi);
  const double dx = step.forward * cm - step.lateral * sm;
  const double dy = step.forward * sm + step.lateral * cm;
  const Eigen::Vector3d predicted(pose_WR.x() + dx, pose_WR.y() + dy,
                                  WrapAngleFast(pose_WR.z() + dth));
  if (A != nullptr) {
    A->setIdentity();
    (*A)(0, 2) = -dy;
    (*A)(1, 2) = dx;
  }
  if (W != nullptr) {
    *W << step.dforward_dd * cm - step.dlateral_dd * sm,
          step.dforward_ddth * cm - step.dlateral_ddth * sm - step.dphi_ddth * dy,
          step.dforward_dd * sm + step.dlateral_dd * cm,
          step.dforward_ddth * sm + step.dlateral_ddth * cm + step.dphi_ddth * dx,
          0.0, 1.0;
  }
  return predicted;
}

// Eq. (6) integrated exactly: the axle centre on the arc, R moving by the
// chord d sinc(dth/2) along the mid-arc heading and by 2 a sin(dth/2) across
// it (h swinging about the axle), less the skid.
PlanarStep ExactStep(double th, double d, double dth, double a_m, double skid_per_m_rad) {
  const double half = 0.5 * dth;
  // sinc(half) and its derivative with respect to dth.
  double sinc, dsinc;
  if (std::abs(half) < 1e-4) {
    sinc = 1.0 - half * half / 6.0;
    dsinc = -half / 6.0;
  } else {
    sinc = std::sin(half) / half;
    dsinc = 0.5 * (half * std::cos(half) - std::sin(half)) / (half * half);
  }
  PlanarStep step;
  step.phi = th + half;
  step.dphi_ddth = 0.5;
  step.forward = d * sinc;
  step.dforward_dd = sinc;
  step.dforward_ddth = d * dsinc;
  // Sideways: the point h swinging about the axle and the skid outward.
  step.lateral = 2.0 * a_m * std::sin(half) - skid_per_m_rad * d * dth;
  step.dlateral_dd = -skid_per_m_rad * dth;
  step.dlateral_ddth = a_m * std::cos(half) - skid_per_m_rad * d;
  return step;
}

// The paper's forward-Euler Eq. (6): d along the start heading th, a dth
// across it for the point h ahead of the axle, less the skid.
PlanarStep EulerStep(double th, double d, double dth, double a_m, double skid_per_m_rad) {
  PlanarStep step;
  step.phi = th;
  step.forward = d;
  step.dforward_dd = 1.0;
  step.lateral = a_m * dth - skid_per_m_rad * d * dth;
  step.dlateral_dd = -skid_per_m_rad * dth;
  step.dlateral_ddth = a_m - skid_per_m_rad * d;
  return step;
}

}  // namespace

Eigen::Vector3d PredictPose(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& increment,
                            double a_m, Eigen::Matrix3d* A, Eigen::Matrix<double, 3, 2>* W,
                            double skid_per_m_rad, MotionIntegration integration) {
  const double d = increment.x();
  const double dth = increment.y();
  const PlanarStep step =
      integration == MotionIntegration::kEuler
          ? EulerStep(pose_WR.z(), d, dth, a_m, skid_per_m_rad)
          : ExactStep(pose_WR.z(), d, dth, a_m, skid_per_m_rad);
  return ApplyStep(pose_WR, dth, step, A, W);
}

MotionInput CommandInput(const Twist2& command, double dt_s, const CommandNoiseParams& noise,
                         const Twist2& previous) {
  MotionInput input;
  input.increment = Eigen::Vector2d(command.v_mps * dt_s, command.w_radps * dt_s);
  const double sigma_v = noise.v_std_mps + noise.v_fraction * std::abs(command.v_mps) +
                         noise.change_fraction * std::abs(command.v_mps - previous.v_mps);
  const double sigma_w = noise.w_std_radps +
                         noise.w_fraction * std::abs(command.w_radps) +
                         noise.change_fraction * std::abs(command.w_radps - previous.w_radps);
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
      noise.distance_std_m * noise.distance_std_m +
      noise.distance_std_m_per_sqrt_m * noise.distance_std_m_per_sqrt_m * distance +
      noise.distance_std_m_per_sqrt_rad * noise.distance_std_m_per_sqrt_rad * turn;
  const double variance_th =
      noise.heading_std_rad * noise.heading_std_rad +
      noise.heading_std_rad_per_sqrt_m * noise.heading_std_rad_per_sqrt_m * distance +
      noise.heading_std_rad_per_sqrt_rad * noise.heading_std_rad_per_sqrt_rad * turn;
  input.covariance = Eigen::Vector2d(variance_d, variance_th).asDiagonal();
  return input;
}

}  // namespace mjslam::slam
