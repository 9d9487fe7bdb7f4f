#pragma once

#include <optional>

#include <Eigen/Core>

#include "common/pose2.h"
#include "common/records.h"
#include "slam/slam_params.h"

namespace mjslam::slam {

/// The input of the paper's Eq. (6) integrated over one record: the products
/// `u dt` (distance, metres) and `w dt` (heading change, radians). The filter
/// works with these increments so that dt = 0 and odometry need no division.
struct MotionInput {
  /// (u dt, w dt): metres, radians.
  Eigen::Vector2d increment = Eigen::Vector2d::Zero();
  /// Covariance of `increment` (the paper's Q, scaled by dt^2 for commands).
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  /// Variance of a sideways slip of R over the step, m^2: a displacement
  /// across the mid-arc heading th + dth / 2 that Eq. (6) does not model,
  /// independent of `increment` (LateralMotionParams::slip_std_m_per_rad and
  /// slip_std_m_per_sqrt_m).
  double lateral_variance_m2 = 0.0;
  /// Skid to the outside of the turn, per metre and radian of `increment`:
  /// R moves by -skid d dth across the mid-arc heading (LateralMotionParams::skid_s
  /// divided by dt). 0: Eq. (6) alone.
  double skid_per_m_rad = 0.0;
  /// How Eq. (6) is integrated over the step (ProcessModel::integration).
  MotionIntegration integration = MotionIntegration::kExact;
  /// Variance of each wheel's slip fraction per metre it rolls, with
  /// self-calibration (SelfCalibrationParams::wheel_slip_drift_std_per_sqrt_m
  /// squared); 0: the odometry's errors are constant.
  double wheel_slip_drift_per_m = 0.0;
  /// The wheels' track, metres, for self-calibration's term k B^2 / 4 dth
  /// (EkfParams::axle_track_m); unused without it.
  double axle_track_m = 0.0;
  /// With self-calibration: the increment the derivatives by (q_d, q_th, k)
  /// are taken at, free of the odometry's noise (EkfSlam gives the held
  /// command times dt); `increment` when not set.
  std::optional<Eigen::Vector2d> calibration_jacobian_increment;
};

/// The paper's Eq. (6) for the point of control h (frame R, `a_m` ahead of
/// the wheel axle), pose (x, y, th) of R in W and increment (d, dth) = (u dt,
/// w dt):
///   x' = x + d cos th - a dth sin th,  y' = y + d sin th + a dth cos th,
///   th' = wrap(th + dth),
/// integrated exactly (kExact: the axle centre on an arc, docs/method.md
/// departure 9), plus a skid of -skid_per_m_rad d dth across the mid-arc
/// heading (MotionInput::skid_per_m_rad); or, with kEuler, the forward-Euler
/// step above as the paper writes it, the skid then across the start
/// heading th. If not null, `A` receives d pose' / d pose and `W` d pose' / d
/// increment, of the integration chosen.
Eigen::Vector3d PredictPose(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& increment,
                            double a_m, Eigen::Matrix3d* A = nullptr,
                            Eigen::Matrix<double, 3, 2>* W = nullptr,
                            double skid_per_m_rad = 0.0,
                            MotionIntegration integration = MotionIntegration::kExact);

/// The command (v, w) held over `dt_s` (>= 0) as an input: increment
/// (v dt, w dt), covariance diag((dt sigma_v)^2, (dt sigma_w)^2) with
///   sigma_v = v_std_mps + v_fraction |v| + change_fraction |v - previous.v|,
/// sigma_w likewise, `previous` the command of the record before
/// (CommandNoiseParams).
MotionInput CommandInput(const Twist2& command, double dt_s, const CommandNoiseParams& noise,
                         const Twist2& previous);

/// The wheel-odometry increment between two records as the equivalent input:
/// the (d, dth) that PredictPose with offset `a_m` turns into the motion
/// X_OR_previous^-1 * X_OR (exactly when that motion is a unicycle arc of the
/// axle centre; its lateral slip, if any, is dropped). Covariance from
/// `noise` (OdometryNoiseParams documents it).
MotionInput OdometryInput(const Pose2& X_OR_previous, const Pose2& X_OR, double a_m,
                          const OdometryNoiseParams& noise);

}  // namespace mjslam::slam
