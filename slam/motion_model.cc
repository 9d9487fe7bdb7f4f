#include "slam/motion_model.h"

#include <algorithm>
#include <cmath>
#include <utility>

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
PlanarStep ExactStep(double th, double d, double dth, double a_m, double skid_per_m_rad,
                     const TurnCentre& centre) {
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
  // The turn about a point beside the axle: the axle, c_prev to the left of
  // that point at the start heading th and c at th + dth, moves by
  // c n(th + dth) - c_prev n(th) (n the left normal), which is
  // -(c + c_prev) sin(dth/2) along the mid-arc heading and
  // (c - c_prev) cos(dth/2) across it.
  const double sum = centre.offset_m + centre.previous_offset_m;
  const double change = centre.offset_m - centre.previous_offset_m;
  if (sum != 0.0 || change != 0.0) {
    const double s = std::sin(half);
    const double c = std::cos(half);
    step.forward -= sum * s;
    step.dforward_ddth -= 0.5 * sum * c;
    step.lateral += change * c;
    step.dlateral_ddth -= 0.5 * change * s;
  }
  return step;
}

// The paper's forward-Euler Eq. (6): d along the start heading th, a dth
// across it for the point h ahead of the axle, less the skid, plus the turn
// about a point beside the axle to first order: c n(th + dth) - c_prev n(th)
// with n(th + dth) ~ n(th) - dth f(th) (f the heading's unit vector).
PlanarStep EulerStep(double th, double d, double dth, double a_m, double skid_per_m_rad,
                     const TurnCentre& centre) {
  PlanarStep step;
  step.phi = th;
  step.forward = d;
  step.dforward_dd = 1.0;
  step.lateral = a_m * dth - skid_per_m_rad * d * dth;
  step.dlateral_dd = -skid_per_m_rad * dth;
  step.dlateral_ddth = a_m - skid_per_m_rad * d;
  if (centre.offset_m != 0.0 || centre.previous_offset_m != 0.0) {
    step.forward -= centre.offset_m * dth;
    step.dforward_ddth = -centre.offset_m;
    step.lateral += centre.offset_m - centre.previous_offset_m;
  }
  return step;
}

}  // namespace

Eigen::Vector3d PredictPose(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& increment,
                            double a_m, Eigen::Matrix3d* A, Eigen::Matrix<double, 3, 2>* W,
                            double skid_per_m_rad, MotionIntegration integration,
                            const TurnCentre& turn_centre) {
  const double d = increment.x();
  const double dth = increment.y();
  const PlanarStep step =
      integration == MotionIntegration::kEuler
          ? EulerStep(pose_WR.z(), d, dth, a_m, skid_per_m_rad, turn_centre)
          : ExactStep(pose_WR.z(), d, dth, a_m, skid_per_m_rad, turn_centre);
  return ApplyStep(pose_WR, dth, step, A, W);
}

namespace {

// One component of FollowCommand: the lag's step toward `target`.
double FollowThroughLag(double followed, double target, double dt_s, double lag_s) {
  if (lag_s <= 0.0) return target;
  const double beta = -std::expm1(-dt_s / lag_s);  // 1 - exp(-dt / lag), exact for small dt
  return followed + beta * (target - followed);
}

}  // namespace

Twist2 FollowCommand(const Twist2& followed, const Twist2& command, double dt_s,
                     const CommandFollowing& following) {
  double v = FollowThroughLag(followed.v_mps, command.v_mps, dt_s, following.lag_v_s);
  if (following.max_accel_mps2 > 0.0) {
    const double most = following.max_accel_mps2 * dt_s;
    v = followed.v_mps + std::clamp(v - followed.v_mps, -most, most);
  }
  return Twist2{v, FollowThroughLag(followed.w_radps, command.w_radps, dt_s, following.lag_w_s)};
}

RampStep RampCommand(const Twist2& ramped, const Twist2& command, double dt_s, double accel_mps2,
                     double accel_radps2) {
  // One component: (mean, end).
  auto ramp = [dt_s](double from, double to, double accel) {
    if (accel <= 0.0) return std::pair<double, double>{to, to};
    if (dt_s <= 0.0) return std::pair<double, double>{from, from};
    const double change = std::clamp(to - from, -accel * dt_s, accel * dt_s);
    const double reached_s = std::abs(change) / accel;
    const double end = from + change;
    return std::pair<double, double>{end - change * reached_s / (2.0 * dt_s), end};
  };
  const auto [v_mean, v_end] = ramp(ramped.v_mps, command.v_mps, accel_mps2);
  const auto [w_mean, w_end] = ramp(ramped.w_radps, command.w_radps, accel_radps2);
  return RampStep{Twist2{v_mean, w_mean}, Twist2{v_end, w_end}};
}

MotionInput CommandInput(const Twist2& command, double dt_s, const CommandNoiseParams& noise,
                         const Twist2& previous, double gain_v, double gain_w,
                         const Twist2* followed, const Twist2& previous_change) {
  const Twist2& speeds = followed != nullptr ? *followed : command;
  // Departure 29: the relative excess of this record's change and the one
  // before over the range the noise was calibrated on.
  double beyond_v = 0.0;
  double beyond_w = 0.0;
  if (noise.beyond_change_noise_fraction > 0.0) {
    auto excess = [](double change, double range) {
      return std::max(0.0, std::abs(change) - range) / range;
    };
    const double cv = noise.calibrated_change_v_mps;
    const double cw = noise.calibrated_change_w_radps;
    const double x = excess(command.v_mps - previous.v_mps, cv) +
                     excess(command.w_radps - previous.w_radps, cw) +
                     excess(previous_change.v_mps, cv) + excess(previous_change.w_radps, cw);
    beyond_v = noise.beyond_change_noise_fraction * cv * x;
    beyond_w = noise.beyond_change_noise_fraction * cw * x;
  }
  MotionInput input;
  input.increment =
      Eigen::Vector2d(gain_v * speeds.v_mps * dt_s, gain_w * speeds.w_radps * dt_s);
  const double sigma_v =
      noise.v_noise_scale *
      (noise.v_noise_std_mps + noise.v_noise_fraction * std::abs(speeds.v_mps) +
       noise.change_noise_fraction * std::abs(command.v_mps - previous.v_mps) +
       noise.settle_noise_fraction * std::abs(previous_change.v_mps) +
       noise.lag_noise_fraction * std::abs(command.v_mps - speeds.v_mps) +
       noise.turn_v_noise_m_per_rad * std::abs(speeds.w_radps) + beyond_v);
  const double sigma_w =
      noise.w_noise_scale *
      (noise.w_noise_std_radps + noise.w_noise_fraction * std::abs(speeds.w_radps) +
       noise.change_noise_fraction * std::abs(command.w_radps - previous.w_radps) +
       noise.settle_noise_fraction * std::abs(previous_change.w_radps) +
       noise.lag_noise_fraction * std::abs(command.w_radps - speeds.w_radps) +
       noise.speed_w_noise_rad_per_m * std::abs(speeds.v_mps) + beyond_w);
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
      noise.distance_noise_std_m_per_sqrt_m * noise.distance_noise_std_m_per_sqrt_m * distance +
      noise.distance_noise_std_m_per_sqrt_rad * noise.distance_noise_std_m_per_sqrt_rad * turn;
  const double variance_th =
      noise.heading_noise_std_rad * noise.heading_noise_std_rad +
      noise.heading_noise_std_rad_per_sqrt_m * noise.heading_noise_std_rad_per_sqrt_m * distance +
      noise.heading_noise_std_rad_per_sqrt_rad * noise.heading_noise_std_rad_per_sqrt_rad * turn;
  input.covariance = Eigen::Vector2d(variance_d, variance_th).asDiagonal();
  return input;
}

}  // namespace mjslam::slam
