#include "sim/laser_noise.h"

#include <algorithm>

#include "common/angles.h"
#include "common/check.h"

namespace mjslam::sim {

LaserNoise::LaserNoise(const LaserParams& laser, const Rng& run_rng)
    : laser_(laser),
      jitter_rng_(run_rng.Fork("laser.jitter")),
      range_rng_(run_rng.Fork("laser.range")),
      dropout_rng_(run_rng.Fork("laser.dropout")) {
  laser_.ValidateOrThrow();
  // The run's systematic errors: drawn once, always (bias, then scale).
  Rng calibration_rng = run_rng.Fork("laser.calibration");
  range_bias_m_ = calibration_rng.Gaussian(laser_.range_bias_m, laser_.range_bias_std_m);
  range_scale_ =
      1.0 + calibration_rng.Gaussian(laser_.range_scale_fraction, laser_.range_scale_std_fraction);
}

std::vector<double> LaserNoise::DrawAngleOffsets() {
  std::vector<double> offsets(laser_.num_beams, 0.0);
  if (laser_.angle_jitter_std_deg == 0.0) return offsets;
  const double std_rad = DegToRad(laser_.angle_jitter_std_deg);
  for (double& offset : offsets) offset = jitter_rng_.Gaussian(0.0, std_rad);
  return offsets;
}

LaserScan LaserNoise::Apply(const LaserScan& exact) {
  MJSLAM_CHECK(exact.size() == laser_.num_beams);
  MJSLAM_CHECK(static_cast<int>(exact.has_return.size()) == laser_.num_beams);
  MJSLAM_CHECK(exact.max_range_m == laser_.max_range_m);
  LaserScan noisy = exact;
  const double max_range = laser_.max_range_m;
  for (int i = 0; i < exact.size(); ++i) {
    // Draw both numbers for every beam, so beams never shift each other's noise.
    const double error = range_rng_.Gaussian(range_bias_m_, laser_.range_noise_std_m);
    const bool dropped = dropout_rng_.Bernoulli(laser_.dropout_probability);
    if (!exact.has_return[i]) continue;
    if (dropped) {
      noisy.ranges_m[i] = max_range;
      noisy.has_return[i] = 0;
      continue;
    }
    // An echo is a range strictly below the maximum: noise that carries a
    // range to the maximum or beyond turns it into a no-return, as on the
    // SICK, so a recorded scan says the same thing without its flags.
    const double range = std::max(exact.ranges_m[i] * range_scale_ + error, 0.0);
    if (range >= max_range) {
      noisy.ranges_m[i] = max_range;
      noisy.has_return[i] = 0;
    } else {
      noisy.ranges_m[i] = range;
    }
  }
  return noisy;
}

}  // namespace mjslam::sim
