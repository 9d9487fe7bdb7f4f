#pragma once

#include <array>
#include <cstdint>

#include "common/pose2.h"
#include "common/rng.h"
#include "sim/sim_params.h"

namespace mjslam::sim {

/// Dead reckoning from the wheel encoders, as the Pioneer's controller does
/// it: the wheel angles are quantised to whole encoder counts, each wheel's
/// rolled distance gets a seeded error, and the axle pose is integrated along
/// arcs (exact for constant wheel speeds between updates). Returns the pose of
/// frame R (the point h, control_point_offset_m ahead of the axle) in the
/// odometry frame O, which is R's pose at the first update.
///
/// Error model, per wheel (a standard odometry model: Borenstein & Feng,
/// "Measurement and correction of systematic odometry errors", IEEE TRA 1996,
/// separates systematic and random errors the same way):
/// - systematic: the wheel's effective radius is r (1 + e), e ~ N(0,
///   wheel_radius_error_std_fraction), drawn once at construction from the
///   stream "odometry.calibration";
///   likewise the axle track: the wheels are b (1 + e_b) apart, e_b ~
///   N(axle_track_error_fraction, axle_track_error_std_fraction), drawn after
///   the two radii, while the odometry divides by the nominal b;
/// - random slip: each increment ds gets N(0, slip_std_fraction^2 * |ds| * 1 m)
///   added, from the stream "odometry.slip" (two draws per update, left then
///   right), so the error variance grows with the distance rolled and does
///   not depend on how often Update is called;
/// - correlated slip: each wheel's ds is also scaled by 1 + eta, eta a
///   first-order Gauss-Markov process over the wheel's distance rolled
///   (stationary std correlated_slip_std_fraction, correlation length
///   slip_correlation_distance_m), from the stream "odometry.correlated_slip"
///   (draws only when it is on).
/// The wheel angles themselves come from the simulator and already contain
/// the physical slip of the wheels on the floor.
class WheelOdometry {
 public:
  /// Throws ParamError if `robot` or `odometry` is invalid.
  WheelOdometry(const RobotParams& robot, const OdometryParams& odometry,
                const Rng& run_rng);

  /// Reads the encoders at wheel angles {left, right} (rad, forward positive,
  /// unwrapped, as Simulator::WheelAngles returns them) and returns the new
  /// X_OR. The first call only latches the counts and returns the identity.
  Pose2 Update(const std::array<double, 2>& wheel_angles_rad);

  /// The current odometry pose X_OR.
  Pose2 X_OR() const { return X_OA_ * Pose2(a_m_, 0.0, 0.0); }

  /// Encoder counts {left, right} of the last update.
  std::array<std::int64_t, 2> counts() const { return counts_; }

 private:
  RobotParams robot_;
  OdometryParams odometry_;
  Rng slip_rng_;
  Rng correlated_slip_rng_;
  double a_m_;
  double ticks_per_rad_;
  std::array<double, 2> radius_scale_{1.0, 1.0};
  double track_scale_ = 1.0;
  std::array<double, 2> correlated_slip_{0.0, 0.0};
  bool started_ = false;
  std::array<std::int64_t, 2> counts_{0, 0};
  Pose2 X_OA_;  // axle centre A in O
};

}  // namespace mjslam::sim
