#pragma once

// Test-only walls of zero thickness, the exact ray cast against them and the
// contact check of a rectangle: the geometry of the synthetic worlds that the
// slam and explorer tests build without MuJoCo.

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "common/segments.h"

namespace mjslam::testing {

/// A wall of zero thickness from `a` to `b`, in W, metres.
struct Wall {
  Eigen::Vector2d a;
  Eigen::Vector2d b;
};

/// The nearest wall the ray p + t u (|u| = 1, t > 0) meets: its range t and
/// its index, or infinity and -1. Walls closer to parallel to the ray than
/// `min_denominator` (|u x (b - a)|) are not met.
struct RayHit {
  double range_m = std::numeric_limits<double>::infinity();
  int wall = -1;
};
inline RayHit CastRayHit(const std::vector<Wall>& walls, const Eigen::Vector2d& p,
                         const Eigen::Vector2d& u, double min_denominator = 1e-12) {
  RayHit hit;
  for (int k = 0; k < static_cast<int>(walls.size()); ++k) {
    const double t = RaySegmentCast(p, u, walls[k].a, walls[k].b, min_denominator);
    if (t < hit.range_m) {
      hit.range_m = t;
      hit.wall = k;
    }
  }
  return hit;
}

/// Range along the ray p + t u (|u| = 1) to the first wall, or infinity.
inline double CastRay(const std::vector<Wall>& walls, const Eigen::Vector2d& p,
                      const Eigen::Vector2d& u) {
  return CastRayHit(walls, p, u).range_m;
}

/// Whether the segment [p, q] (in the body frame) meets the rectangle
/// [x0, x1] x [-hw, hw] (Liang-Barsky clipping).
inline bool SegmentMeetsRectangle(const Eigen::Vector2d& p, const Eigen::Vector2d& q, double x0,
                                  double x1, double hw) {
  double t0 = 0.0;
  double t1 = 1.0;
  const Eigen::Vector2d d = q - p;
  const double ps[4] = {-d.x(), d.x(), -d.y(), d.y()};
  const double qs[4] = {p.x() - x0, x1 - p.x(), p.y() + hw, hw - p.y()};
  for (int k = 0; k < 4; ++k) {
    if (std::abs(ps[k]) < 1e-15) {
      if (qs[k] < 0.0) return false;
      continue;
    }
    const double t = qs[k] / ps[k];
    if (ps[k] < 0.0) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
    if (t0 > t1) return false;
  }
  return true;
}

/// The polar form (rho, alpha) of the line through `a` and `b` (a != b), in
/// their frame: x cos(alpha) + y sin(alpha) = rho with rho >= 0 and alpha
/// the angle of the line's normal, in (-pi, pi].
inline Eigen::Vector2d PolarLineThrough(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d direction = (b - a).normalized();
  Eigen::Vector2d normal(-direction.y(), direction.x());
  double rho = normal.dot(a);
  if (rho < 0.0) {
    rho = -rho;
    normal = -normal;
  }
  return {rho, std::atan2(normal.y(), normal.x())};
}

/// Walls of an axis-aligned rectangle [x0, x1] x [y0, y1].
inline std::vector<Wall> Box(double x0, double y0, double x1, double y1) {
  return {{{x0, y0}, {x1, y0}}, {{x1, y0}, {x1, y1}}, {{x1, y1}, {x0, y1}}, {{x0, y1}, {x0, y0}}};
}

}  // namespace mjslam::testing
