#pragma once

#include <vector>

#include "common/laser_scan.h"
#include "common/rng.h"
#include "sim/laser_footprint.h"
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
/// The SICK's error structure (docs/method.md, "The SICK's error
/// structure"), opt-in, each effect from a stream of its own drawn only when
/// its key is on (so with every key off the scans are bit for bit those of
/// the model above, and turning one on shifts no other draw):
/// - "laser.grazing": a beam with an echo at incidence theta is lost
///   (max range, no return) with probability
///   p90 * clamp((theta - theta0) / (90 deg - theta0), 0, 1);
/// - "laser.mixed_pixel": a beam whose footprint straddles a depth
///   discontinuity (some sub-ray reads more than mixed_pixel_min_step_m
///   from where the line through its two neighbours' hits crosses it; on a
///   flat surface they line up, however grazing) reads, with probability
///   mixed_pixel_probability, the mean of its sub-rays' echoes instead of
///   its centre range (sub-rays without an echo carry no weight);
/// - "laser.range_growth": the noise's standard deviation grows with the
///   range r read (before the systematic error) to
///   sigma(r) = range_noise_std_m + range_noise_std_per_m * r, by adding an
///   independent N(0, sigma(r)^2 - range_noise_std_m^2) to the draw above;
/// - range_resolution_m: the range is rounded to a multiple of it (no draw).
/// Per beam, in order: the exact scan's no-returns stay; the random dropout;
/// the grazing dropout; the centre or mixed range; (1 + s) r + noise;
/// rounding; the clamp to max range. The structure needs a LaserFootprint
/// (sim/laser_footprint.h) from Simulator::CastLaser for mixed pixels and
/// grazing dropouts.
///
/// Still departures from the SICK LMS200's real behaviour: no dependence on
/// the surface's reflectivity or colour, none on temperature or warm-up
/// (Ye & Borenstein, ICRA 2002), no short readings (Thrun et al., Sec. 6.3).
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
  /// `footprint`: what Simulator::CastLaser cast for the same scan; required
  /// (with its sub-rays, resp. incidences, for every beam) when
  /// laser.HasMixedPixels(), resp. laser.HasGrazingDropouts(), else unused.
  LaserScan Apply(const LaserScan& exact, const LaserFootprint* footprint = nullptr);

  /// Probability of a grazing dropout at incidence `incidence_rad` (0 when
  /// the key is off, or for NaN).
  double GrazingDropoutProbability(double incidence_rad) const;

 private:
  LaserParams laser_;
  double range_bias_m_ = 0.0;
  double range_scale_ = 1.0;
  Rng jitter_rng_;
  Rng range_rng_;
  Rng dropout_rng_;
  Rng grazing_rng_;
  Rng mixed_pixel_rng_;
  Rng range_growth_rng_;
};

}  // namespace mjslam::sim
