#include "sim/wheel_odometry.h"

#include <cmath>

#include "common/angles.h"

namespace mjslam::sim {

WheelOdometry::WheelOdometry(const RobotParams& robot, const OdometryParams& odometry,
                             const Rng& run_rng)
    : robot_(robot),
      odometry_(odometry),
      slip_rng_(run_rng.Fork("odometry.slip")),
      correlated_slip_rng_(run_rng.Fork("odometry.correlated_slip")),
      a_m_(robot.control_point_offset_m),
      ticks_per_rad_(odometry.ticks_per_wheel_revolution / (2.0 * kPi)),
      X_OA_(-robot.control_point_offset_m, 0.0, 0.0) {
  robot_.ValidateOrThrow();
  odometry_.ValidateOrThrow();
  // Systematic errors: drawn once, always (left, right, then the axle
  // track), from their own stream.
  Rng calibration_rng = run_rng.Fork("odometry.calibration");
  const std::array<double, 2> mean{odometry_.left_wheel_radius_error_fraction,
                                   odometry_.right_wheel_radius_error_fraction};
  for (int i = 0; i < 2; ++i) {
    radius_scale_[i] =
        1.0 + calibration_rng.Gaussian(mean[i], odometry_.wheel_radius_error_std_fraction);
  }
  track_scale_ = 1.0 + calibration_rng.Gaussian(odometry_.axle_track_error_fraction,
                                                 odometry_.axle_track_error_std_fraction);
  // The correlated slip starts from its stationary distribution.
  if (odometry_.correlated_slip_std_fraction > 0.0) {
    for (double& slip : correlated_slip_) {
      slip = correlated_slip_rng_.Gaussian(0.0, odometry_.correlated_slip_std_fraction);
    }
  }
}

Pose2 WheelOdometry::Update(const std::array<double, 2>& wheel_angles_rad) {
  // Quantise to whole encoder counts, as the counters do.
  std::array<std::int64_t, 2> counts{};
  for (int i = 0; i < 2; ++i) {
    counts[i] = static_cast<std::int64_t>(std::floor(wheel_angles_rad[i] * ticks_per_rad_));
  }
  if (!started_) {
    started_ = true;
    counts_ = counts;
    return X_OR();
  }

  // Distance rolled by each wheel, with its systematic and random error.
  std::array<double, 2> distance_m{};
  for (int i = 0; i < 2; ++i) {
    const double angle = static_cast<double>(counts[i] - counts_[i]) / ticks_per_rad_;
    const double ds = robot_.wheel_radius_m * radius_scale_[i] * angle;
    const double slip_std = odometry_.slip_std_fraction * std::sqrt(std::abs(ds));
    distance_m[i] = ds * (1.0 + correlated_slip_[i]) + slip_rng_.Gaussian(0.0, slip_std);
  }
  // The correlated slip moves on over the distance rolled (a first-order
  // Gauss-Markov step, exact for any step length).
  if (odometry_.correlated_slip_std_fraction > 0.0) {
    for (int i = 0; i < 2; ++i) {
      const double keep =
          std::exp(-std::abs(distance_m[i]) / odometry_.slip_correlation_distance_m);
      const double std = odometry_.correlated_slip_std_fraction * std::sqrt(1.0 - keep * keep);
      correlated_slip_[i] = keep * correlated_slip_[i] + correlated_slip_rng_.Gaussian(0.0, std);
    }
  }
  counts_ = counts;

  // Axle motion: along an arc with the wheels' mean distance and the heading
  // change of their difference (exact for constant wheel speeds).
  const double ds = 0.5 * (distance_m[0] + distance_m[1]);
  // The true track is axle_track_m * track_scale_; the odometry assumes the
  // nominal one, so its heading change is off by the track's error.
  const double dth = (distance_m[1] - distance_m[0]) / robot_.axle_track_m * track_scale_;
  double dx = 0.0;
  double dy = 0.0;
  if (std::abs(dth) < 1e-9) {
    dx = ds * std::cos(X_OA_.theta + 0.5 * dth);
    dy = ds * std::sin(X_OA_.theta + 0.5 * dth);
  } else {
    const double radius = ds / dth;
    dx = radius * (std::sin(X_OA_.theta + dth) - std::sin(X_OA_.theta));
    dy = -radius * (std::cos(X_OA_.theta + dth) - std::cos(X_OA_.theta));
  }
  X_OA_ = Pose2(X_OA_.x + dx, X_OA_.y + dy, X_OA_.theta + dth);
  return X_OR();
}

}  // namespace mjslam::sim
