#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>

namespace mjslam {

/// The z component of the cross product of two plane vectors,
/// a.x * b.y - a.y * b.x: positive when b turns left of a.
inline double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

/// Distance from the point `p` to the segment from `a` to `b` (a != b), in the
/// units of the arguments: the distance to the segment's point nearest to p.
inline double PointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                                   const Eigen::Vector2d& b) {
  const Eigen::Vector2d e = b - a;
  const double t = std::clamp((p - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
  return (a + t * e - p).norm();
}

/// The parameter t > 0 where the ray p + t u meets the segment from `a` to `b`
/// (end points included), or infinity when it does not, or when the ray and
/// the segment are parallel (|u x (b - a)| < `min_denominator`). With |u| = 1,
/// t is the distance from p.
inline double RaySegmentCast(const Eigen::Vector2d& p, const Eigen::Vector2d& u,
                             const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                             double min_denominator = 1e-12) {
  const Eigen::Vector2d e = b - a;
  const double denominator = Cross(u, e);
  if (std::abs(denominator) < min_denominator) return std::numeric_limits<double>::infinity();
  const Eigen::Vector2d d = a - p;
  const double t = Cross(d, e) / denominator;
  const double s = Cross(d, u) / denominator;
  if (t > 0.0 && s >= 0.0 && s <= 1.0) return t;
  return std::numeric_limits<double>::infinity();
}

/// The point where the infinite lines through (a0, a1) and (b0, b1) meet;
/// they must not be parallel.
inline Eigen::Vector2d LineIntersection(const Eigen::Vector2d& a0, const Eigen::Vector2d& a1,
                                        const Eigen::Vector2d& b0, const Eigen::Vector2d& b1) {
  const Eigen::Vector2d da = a1 - a0;
  const Eigen::Vector2d db = b1 - b0;
  const double t = Cross(b0 - a0, db) / Cross(da, db);
  return a0 + t * da;
}

}  // namespace mjslam
