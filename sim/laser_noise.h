#pragma once

#include <vector>

#include "common/laser_scan.h"
#include "common/rng.h"
#include "sim/sim_params.h"

namespace mjslam::sim {

/// The laser's error model, applied to exact scans (Simulator::CastLaser) so
/// that the casting stays testable against geometry without statistics.
///
/// Per beam, each from its own random stream forked from the run's Rng (so
/// turning one effect on or off never shifts the numbers of the others):
/// - "laser.jitter": angular jitter, N(0, angle_jitter_std_deg). The beam is
///   actually cast at nominal + offset (DrawAngleOffsets, passed to
///   Simulator::CastLaser) but reported at its nominal angle.
/// - "laser.calibration": the run's systematic errors, drawn once: the bias
///   b ~ N(range_bias_m, range_bias_std_m) and the scale error s ~
///   N(range_scale_fraction, range_scale_std_fraction);
/// - "laser.range": range noise: every beam that has an echo reads
///   range (1 + s) + N(b, range_noise_std_m).
/// - "laser.dropout": with dropout_probability the echo is lost: the beam
///   becomes a no-return at max range.
/// Ranges are clamped to [0, max_range_m]; a beam with an echo keeps it even
/// when clamped to max_range_m. No-return beams of the exact scan stay as they
/// are. Every beam consumes the same random draws whatever its outcome, so a
/// scan's noise depends only on the seed and the scan count.
///
/// Departures from the SICK LMS200's real behaviour (Ye & Borenstein, ICRA
/// 2002: range error depends on incidence angle, surface and temperature;
/// mixed pixels at edges): the model here is the simple independent Gaussian
/// of Probabilistic Robotics' beam model (Thrun et al., Sec. 6.3, the p_hit
/// and p_max parts only; no short readings, no random readings).
class LaserNoise {
 public:
  /// `run_rng` is the run's root stream; the three named streams are forked
  /// from it. Throws ParamError if `laser` is invalid.
  LaserNoise(const LaserParams& laser, const Rng& run_rng);

  /// Per-beam angle offsets, radians, in beam order (num_beams values): the
  /// angles at which the next scan's beams are really cast. All zeros (and no
  /// random draws) when angle_jitter_std_deg is 0.
  std::vector<double> DrawAngleOffsets();

  /// The exact scan with range noise, bias and dropouts added. `exact` must
  /// have num_beams beams and max_range_m equal to the params' (checked).
  LaserScan Apply(const LaserScan& exact);

 private:
  LaserParams laser_;
  double range_bias_m_ = 0.0;
  double range_scale_ = 1.0;
  Rng jitter_rng_;
  Rng range_rng_;
  Rng dropout_rng_;
};

}  // namespace mjslam::sim
