#pragma once

#include <vector>

namespace mjslam::sim {

/// What the laser's error structure (LaserNoise, sim/laser_noise.h) needs of
/// one sweep beyond its exact ranges. Simulator::CastLaser fills it when
/// given one, casting only what the LaserParams' structure keys use:
/// - mixed pixels (laser.mixed_pixel_probability > 0): `rays_per_beam` =
///   laser.footprint_rays sub-rays per beam, spread evenly over the beam's
///   footprint, from -beam_divergence_deg / 2 to +beam_divergence_deg / 2
///   about the beam's cast bearing (its nominal bearing plus its jitter);
/// - grazing dropouts (laser.grazing_dropout_probability > 0): the incidence
///   angle per beam, from two probe rays kProbeRad either side of the beam:
///   the angle between the beam and the normal of the line through their two
///   hits (exact on a flat surface; on an edge or a curved surface, the
///   chord's normal).
/// Left empty for what is off, so a LaserNoise whose structure keys are all
/// off never reads it.
struct LaserFootprint {
  /// Half the angle between the two incidence probe rays, radians.
  static constexpr double kProbeRad = 1e-4;

  /// Sub-rays per beam in `sub_ranges_m` (0: none cast).
  int rays_per_beam = 0;
  /// Beam i's sub-ray j at sub_ranges_m[i * rays_per_beam + j], j = 0 the
  /// rightmost (most clockwise); exactly max_range_m where it has no echo.
  std::vector<double> sub_ranges_m;
  /// Per beam, the angle of incidence in radians, in [0, pi/2]; NaN where the
  /// beam or either probe has no echo. Empty when not cast.
  std::vector<double> incidence_rad;
};

}  // namespace mjslam::sim
