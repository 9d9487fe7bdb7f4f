#pragma once

#include <cstdint>
#include <vector>

namespace mjslam {

/// One sweep of a planar range finder, in the sensor frame S (x forward,
/// y left). Beam i points at `angle_min_rad + i * angle_increment_rad`.
struct LaserScan {
  /// Time of the sweep in seconds since the start of the run.
  double t_s = 0.0;
  /// Bearing of beam 0 in S, radians (-pi/2 for the SICK: its 0 degree beam).
  double angle_min_rad = 0.0;
  /// Angle between consecutive beams, radians.
  double angle_increment_rad = 0.0;
  /// Maximum range in metres; a beam without echo reports exactly this.
  double max_range_m = 0.0;
  /// Measured range per beam, metres.
  std::vector<double> ranges_m;
  /// 1 where the beam returned an echo, 0 for no-return (range = max).
  std::vector<std::uint8_t> has_return;

  /// Number of beams.
  int size() const { return static_cast<int>(ranges_m.size()); }
  /// Bearing of beam `i` in S, radians.
  double BeamAngle(int i) const { return angle_min_rad + i * angle_increment_rad; }
};

}  // namespace mjslam
