#pragma once

#include "common/angles.h"

namespace mjslam::slam {

/// WrapAngle (common/angles.h) with a fast path, exactly equal to it (only
/// the sign of a zero result may differ, e.g. for -2 pi): an
/// angle in (-pi, pi] is returned as is, one in (-3 pi, 3 pi) is shifted by
/// one 2 pi (exact by Sterbenz's lemma, so equal to std::remainder's exact
/// result), anything else (and NaN) goes to WrapAngle. The filter wraps
/// angles in its per-feature loops, where std::remainder cost more than the
/// rest of the association.
inline double WrapAngleFast(double angle_rad) {
  constexpr double kTwoPi = 2.0 * kPi;
  constexpr double kThreePi = 3.0 * kPi;
  if (angle_rad > -kPi && angle_rad <= kPi) return angle_rad;
  if (angle_rad > kPi && angle_rad < kThreePi) return angle_rad - kTwoPi;
  if (angle_rad <= -kPi && angle_rad > -kThreePi) return angle_rad + kTwoPi;
  return WrapAngle(angle_rad);
}

}  // namespace mjslam::slam
