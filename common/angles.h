#pragma once

#include <cmath>

namespace mjslam {

inline constexpr double kPi = 3.14159265358979323846;

/// Wraps an angle in radians to (-pi, pi].
inline double WrapAngle(double angle_rad) {
  double wrapped = std::remainder(angle_rad, 2.0 * kPi);  // in [-pi, pi]
  if (wrapped <= -kPi) wrapped += 2.0 * kPi;
  return wrapped;
}

/// Degrees to radians.
inline constexpr double DegToRad(double deg) { return deg * kPi / 180.0; }

/// Radians to degrees.
inline constexpr double RadToDeg(double rad) { return rad * 180.0 / kPi; }

}  // namespace mjslam
