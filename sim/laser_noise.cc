#include "sim/laser_noise.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "common/angles.h"
#include "common/check.h"

namespace mjslam::sim {

LaserNoise::LaserNoise(const LaserParams& laser, const Rng& run_rng)
    : laser_(laser),
      jitter_rng_(run_rng.Fork("laser.jitter")),
      range_rng_(run_rng.Fork("laser.range")),
      dropout_rng_(run_rng.Fork("laser.dropout")),
      grazing_rng_(run_rng.Fork("laser.grazing")),
      mixed_pixel_rng_(run_rng.Fork("laser.mixed_pixel")),
      range_growth_rng_(run_rng.Fork("laser.range_growth")) {
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

double LaserNoise::GrazingDropoutProbability(double incidence_rad) const {
  if (!laser_.HasGrazingDropouts() || std::isnan(incidence_rad)) return 0.0;
  const double start = DegToRad(laser_.grazing_dropout_start_deg);
  const double rise = std::clamp((incidence_rad - start) / (0.5 * kPi - start), 0.0, 1.0);
  return laser_.grazing_dropout_probability * rise;
}

namespace {

// The mean of a footprint's sub-ray echoes when the footprint straddles a
// depth discontinuity, else nothing. `sub` holds `n` ranges (max_range where
// no echo) of sub-rays at bearings (j / (n - 1) - 1/2) `divergence_rad`. A
// discontinuity: some sub-ray j whose neighbours both have echoes reads more
// than `min_step` from where the line through their two hits crosses it (on
// a flat surface the hits line up exactly, however grazing the beam).
std::optional<double> MixedRange(const double* sub, int n, double max_range, double min_step,
                                 double divergence_rad) {
  auto point = [&](int j) {
    const double bearing = divergence_rad * (static_cast<double>(j) / (n - 1) - 0.5);
    return std::array<double, 2>{sub[j] * std::cos(bearing), sub[j] * std::sin(bearing)};
  };
  bool straddles = false;
  for (int j = 1; j + 1 < n && !straddles; ++j) {
    if (!(sub[j - 1] < max_range && sub[j] < max_range && sub[j + 1] < max_range)) continue;
    const std::array<double, 2> a = point(j - 1);
    const std::array<double, 2> b = point(j + 1);
    const std::array<double, 2> q = point(j);
    const double ux = q[0] / sub[j];
    const double uy = q[1] / sub[j];
    const double dx = b[0] - a[0];
    const double dy = b[1] - a[1];
    // s u = a + t (b - a): s = (a x d) / (u x d).
    const double denominator = ux * dy - uy * dx;
    const double numerator = a[0] * dy - a[1] * dx;
    straddles = std::abs(denominator) < 1e-15 ||
                std::abs(numerator / denominator - sub[j]) > min_step;
  }
  if (!straddles) return std::nullopt;
  double sum = 0.0;
  int hits = 0;
  for (int j = 0; j < n; ++j) {
    if (sub[j] < max_range) {
      sum += sub[j];
      ++hits;
    }
  }
  return sum / hits;
}

}  // namespace

LaserScan LaserNoise::Apply(const LaserScan& exact, const LaserFootprint* footprint) {
  MJSLAM_CHECK(exact.size() == laser_.num_beams);
  MJSLAM_CHECK(static_cast<int>(exact.has_return.size()) == laser_.num_beams);
  MJSLAM_CHECK(exact.max_range_m == laser_.max_range_m);
  const bool mixed_pixels = laser_.HasMixedPixels();
  const bool grazing = laser_.HasGrazingDropouts();
  const bool range_growth = laser_.range_noise_std_per_m > 0.0;
  const int rays = mixed_pixels ? laser_.footprint_rays : 0;
  if (mixed_pixels) {
    MJSLAM_CHECK(footprint != nullptr && footprint->rays_per_beam == rays);
    MJSLAM_CHECK(static_cast<int>(footprint->sub_ranges_m.size()) == exact.size() * rays);
  }
  if (grazing) {
    MJSLAM_CHECK(footprint != nullptr);
    MJSLAM_CHECK(static_cast<int>(footprint->incidence_rad.size()) == exact.size());
  }
  LaserScan noisy = exact;
  const double max_range = laser_.max_range_m;
  for (int i = 0; i < exact.size(); ++i) {
    // Draw both numbers for every beam, so beams never shift each other's noise.
    const double error = range_rng_.Gaussian(range_bias_m_, laser_.range_noise_std_m);
    const bool dropped = dropout_rng_.Bernoulli(laser_.dropout_probability);
    // The structure's draws, each only when its key is on (own streams).
    const double grazing_u = grazing ? grazing_rng_.Uniform() : 1.0;
    const double mixed_u = mixed_pixels ? mixed_pixel_rng_.Uniform() : 1.0;
    const double growth_z = range_growth ? range_growth_rng_.Gaussian(0.0, 1.0) : 0.0;
    if (!exact.has_return[i]) continue;
    if (dropped ||
        (grazing && grazing_u < GrazingDropoutProbability(footprint->incidence_rad[i]))) {
      noisy.ranges_m[i] = max_range;
      noisy.has_return[i] = 0;
      continue;
    }
    double true_range = exact.ranges_m[i];
    if (mixed_pixels && mixed_u < laser_.mixed_pixel_probability) {
      const std::optional<double> mixed =
          MixedRange(footprint->sub_ranges_m.data() + static_cast<std::size_t>(i) * rays, rays,
                     max_range, laser_.mixed_pixel_min_step_m,
                     DegToRad(laser_.beam_divergence_deg));
      if (mixed) true_range = *mixed;
    }
    // An echo is a range strictly below the maximum: noise that carries a
    // range to the maximum or beyond turns it into a no-return, as on the
    // SICK, so a recorded scan says the same thing without its flags.
    double range = std::max(true_range * range_scale_ + error, 0.0);
    if (range_growth) {
      // sigma(r)^2 = a^2 + extra^2: the extra part on top of the draw above.
      const double a = laser_.range_noise_std_m;
      const double sigma = a + laser_.range_noise_std_per_m * true_range;
      range = std::max(range + std::sqrt(sigma * sigma - a * a) * growth_z, 0.0);
    }
    if (laser_.range_resolution_m > 0.0) {
      range = std::round(range / laser_.range_resolution_m) * laser_.range_resolution_m;
    }
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
