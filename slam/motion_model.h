#pragma once

#include <Eigen/Core>

#include "common/pose2.h"
#include "common/records.h"
#include "slam/slam_params.h"

namespace mjslam::slam {

/// Where the robot turns about, when not about its axle centre: the axle
/// lies `offset_m` to the left of that point (across the heading) at the end
/// of the step and `previous_offset_m` at its start; the point stays where it
/// is in W over the step. So the axle moves by
///   offset_m n(th + dth) - previous_offset_m n(th),
/// n(th) = (-sin th, cos th) the left normal: sideways by the change of the
/// offset (a shift when the turn rate changes) and, with the offset held,
/// around the point (-2 offset_m sin(dth / 2) along the mid-arc heading:
/// backward when the point lies on the outside of the turn).
struct TurnCentre {
  double offset_m = 0.0;
  double previous_offset_m = 0.0;
};

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
  /// independent of `increment` (EkfParams::lateral_slip_std_m_per_rad).
  double lateral_variance_m2 = 0.0;
  /// Skid to the outside of the turn, per metre and radian of `increment`:
  /// R moves by -skid d dth across the mid-arc heading (EkfParams::lateral_skid_s
  /// divided by dt). 0: Eq. (6) alone.
  double skid_per_m_rad = 0.0;
  /// The point the robot turns about on the spot, beside its axle
  /// (EkfParams::turn_centre_offset_m_per_radps). Zero: the axle itself.
  TurnCentre turn_centre;
  /// How Eq. (6) is integrated over the step (EkfParams::motion_integration).
  MotionIntegration integration = MotionIntegration::kExact;
  /// The wheels' track, metres, for self-calibration's term k B^2 / 4 dth
  /// (EkfParams::axle_track_m); unused without it.
  double axle_track_m = 0.0;
};

/// The paper's Eq. (6) for the point of control h (frame R, `a_m` ahead of
/// the wheel axle), pose (x, y, th) of R in W and increment (d, dth) = (u dt,
/// w dt):
///   x' = x + d cos th - a dth sin th,  y' = y + d sin th + a dth cos th,
///   th' = wrap(th + dth),
/// integrated exactly (kExact: the axle centre on an arc, docs/method.md
/// departure 9), plus a skid of -skid_per_m_rad d dth across the mid-arc
/// heading (MotionInput::skid_per_m_rad) and the turn about `turn_centre`
/// (TurnCentre: exactly, the point fixed over the step); or, with kEuler,
/// the forward-Euler step above as the paper writes it, the skid then across
/// the start heading th and the turn about `turn_centre` to first order in
/// dth. If not null, `A` receives d pose' / d pose and `W` d pose' / d
/// increment, of the integration chosen.
Eigen::Vector3d PredictPose(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& increment,
                            double a_m, Eigen::Matrix3d* A = nullptr,
                            Eigen::Matrix<double, 3, 2>* W = nullptr,
                            double skid_per_m_rad = 0.0,
                            MotionIntegration integration = MotionIntegration::kExact,
                            const TurnCentre& turn_centre = TurnCentre());

/// The speeds the robot moves at over a step of `dt_s` (>= 0) when it
/// follows `command` as `following` says, having moved at `followed` over
/// the step before: each component through a first-order lag of its own
/// time constant tau,
///   followed + (1 - exp(-dt / tau)) (command - followed)
/// (tau = 0: the command itself), the speed's change over the step then
/// held within +-max_accel dt when a limit is set (the drive's torque
/// limit: a large step of the command is followed at a bounded
/// acceleration, a small one through the lag).
Twist2 FollowCommand(const Twist2& followed, const Twist2& command, double dt_s,
                     const CommandFollowing& following);

/// A robot's own ramp of its set points (departure 28): over a step of
/// `dt_s` (>= 0) the set point moves from `ramped` toward `command` at
/// `accel_mps2` (speed) and `accel_radps2` (turn rate) until it reaches the
/// command, then holds. RampStep's `end` is where it is at the end of the
/// step, `mean` its mean over the step, what the wheels then follow (a
/// component whose acceleration is <= 0 is not ramped: both the command).
struct RampStep {
  Twist2 mean;
  Twist2 end;
};
RampStep RampCommand(const Twist2& ramped, const Twist2& command, double dt_s, double accel_mps2,
                     double accel_radps2);

/// The command held over `dt_s` (>= 0) as an input: increment (g_v v dt,
/// g_w w dt) of the speeds (v, w) the robot moves at, `*followed` when not
/// null (FollowCommand) else `command`, with the gains `gain_v`, `gain_w`
/// (EkfParams::command_gain_v, _w: the mean ratio of the robot's true speeds
/// to its commands); covariance diag((dt sigma_v)^2, (dt sigma_w)^2) with
///   sigma_v = v_noise_scale (v_noise_std_mps + v_noise_fraction |v|
///             + change_noise_fraction |command.v - previous.v|
///             + settle_noise_fraction |previous_change.v|
///             + lag_noise_fraction |command.v - v|
///             + turn_v_noise_m_per_rad |w|
///             + beyond_change_noise_fraction calibrated_change_v_mps x),
/// sigma_w likewise with w for v, speed_w_noise_rad_per_m |v| in place of
/// the wheels' term and calibrated_change_w_radps in the last, x the
/// relative excess of the changes over the calibrated range (departure 29:
/// sum over this record's change and `previous_change`, v and w, of
/// max(0, |change| - calibrated) / calibrated; 0 unless
/// beyond_change_noise_fraction > 0),
/// `previous` being the command of the record before and `previous_change`
/// the change of the command at that record (its command less the one
/// before it; zero at the first records) (CommandNoiseParams).
MotionInput CommandInput(const Twist2& command, double dt_s, const CommandNoiseParams& noise,
                         const Twist2& previous, double gain_v = 1.0, double gain_w = 1.0,
                         const Twist2* followed = nullptr, const Twist2& previous_change = {});

/// The wheel-odometry increment between two records as the equivalent input:
/// the (d, dth) that PredictPose with offset `a_m` turns into the motion
/// X_OR_previous^-1 * X_OR (exactly when that motion is a unicycle arc of the
/// axle centre; its lateral slip, if any, is dropped). Covariance from
/// `noise` (OdometryNoiseParams documents it).
MotionInput OdometryInput(const Pose2& X_OR_previous, const Pose2& X_OR, double a_m,
                          const OdometryNoiseParams& noise);

}  // namespace mjslam::slam
