#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

namespace mjslam::slam {

/// The paper's secondary map for one line feature (r, al): the part of the
/// wall actually seen, stored as positions along the line's direction
/// t = (-sin al, cos al), metres. Its endpoints are r n + s t with
/// n = (cos al, sin al) and s in [s_min, s_max], so they always lie on the
/// current line estimate: projection onto the corrected line is automatic.
struct LineSegment {
  double s_min = 0.0;
  double s_max = 0.0;
};

/// Position along the line (r, al) of the projection of point p_W, metres.
inline double PositionAlongLine(const Eigen::Vector2d& line_W, const Eigen::Vector2d& p_W) {
  return -std::sin(line_W.y()) * p_W.x() + std::cos(line_W.y()) * p_W.y();
}

/// The point of the line (r, al) at position s, in W, metres.
inline Eigen::Vector2d PointOnLine(const Eigen::Vector2d& line_W, double s) {
  const double c = std::cos(line_W.y());
  const double s_al = std::sin(line_W.y());
  return {line_W.x() * c - s * s_al, line_W.x() * s_al + s * c};
}

/// The segment of the seen points p_WA, p_WB of line (r, al).
inline LineSegment SegmentFromPoints(const Eigen::Vector2d& line_W, const Eigen::Vector2d& p_WA,
                                     const Eigen::Vector2d& p_WB) {
  const double s_a = PositionAlongLine(line_W, p_WA);
  const double s_b = PositionAlongLine(line_W, p_WB);
  return {std::min(s_a, s_b), std::max(s_a, s_b)};
}

/// The gap between two segments of one line, metres: how far apart their
/// nearest ends are (negative where they overlap).
inline double SegmentGap(const LineSegment& a, const LineSegment& b) {
  return std::max(a.s_min - b.s_max, b.s_min - a.s_max);
}

/// `segment` extended to cover the projections of p_WA and p_WB on the line
/// (r, al): a wall seen further along grows its segment, never shrinks it.
inline LineSegment ExtendSegment(const LineSegment& segment, const Eigen::Vector2d& line_W,
                                 const Eigen::Vector2d& p_WA, const Eigen::Vector2d& p_WB) {
  const LineSegment seen = SegmentFromPoints(line_W, p_WA, p_WB);
  return {std::min(segment.s_min, seen.s_min), std::max(segment.s_max, seen.s_max)};
}

}  // namespace mjslam::slam
