#pragma once

// The stages of BuildGroundTruthMap and ReachableFeatures (eval/ground_truth.h),
// exposed so that tests can check each indexed stage against the direct
// quadratic one it replaced. Not for use outside eval/ and its tests.

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/box_grid.h"
#include "common/grid2.h"
#include "eval/ground_truth.h"

namespace mjslam::eval::detail {

/// A rectangle as centre, unit axes and half extents, corners counter-clockwise.
struct Rectangle {
  Eigen::Vector2d center;
  Eigen::Vector2d u;  ///< unit axis along the first side
  Eigen::Vector2d v;  ///< unit axis along the second side (u rotated +90 deg)
  double half_u = 0.0;
  double half_v = 0.0;
  std::array<Eigen::Vector2d, 4> corners;  ///< counter-clockwise

  /// p in the rectangle's own coordinates.
  Eigen::Vector2d Local(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d d = p - center;
    return {d.dot(u), d.dot(v)};
  }
  /// Inside the closed rectangle grown by `margin` on every side.
  bool Contains(const Eigen::Vector2d& p, double margin) const {
    const Eigen::Vector2d q = Local(p);
    return std::abs(q.x()) <= half_u + margin && std::abs(q.y()) <= half_v + margin;
  }
};

/// The checked rectangle of wall `index`; throws std::invalid_argument naming
/// it (see BuildGroundTruthMap).
Rectangle MakeRectangle(const WallRectangle& wall, int index, double min_side);

/// The axis-aligned bounds of `r` grown by `margin`, metres.
Box2 BoundsOf(const Rectangle& r, double margin);

/// Parameter interval [t0, t1] of the segment a + t d (t in [0, length], |d| =
/// 1) inside the rectangle grown by `margin` (slab clipping). False if none.
bool ClipSegment(const Rectangle& r, const Eigen::Vector2d& a, const Eigen::Vector2d& d,
                 double length, double margin, double* t0, double* t1);

/// A straight piece of the union's boundary, traversed with the obstacle on
/// its left: from a to b, outward (free-side) normal n.
struct Piece {
  Eigen::Vector2d a;
  Eigen::Vector2d b;
  Eigen::Vector2d n;
};

/// True when q lies on p's line (within `tolerance`) facing the same way.
bool SameLine(const Piece& p, const Piece& q, double tolerance);

/// Every rectangle edge split where it enters or leaves another rectangle
/// (grown by touch_tolerance_m), keeping the pieces whose outside is free:
/// in order of rectangle, edge and position along the edge.
std::vector<Piece> BoundaryPieces(const std::vector<Rectangle>& rects,
                                  const GroundTruthParams& params);

/// Pieces on one line (SameLine) that overlap or touch (within 2 tolerances)
/// merged into one: each group keeps the place of its first piece and runs
/// from the start of its piece that starts first to the end of the one that
/// ends last. Segments shorter than min_segment_length_m are then dropped.
std::vector<Piece> MergeCollinear(std::vector<Piece> pieces, const GroundTruthParams& params);

/// For each segment i, the segment j != i whose start is nearest to i's end
/// within `join_m` (the last such j on ties), or -1.
std::vector<int> NextSegments(const std::vector<Piece>& segments, double join_m);

/// Cells of `limits` whose centre lies in a rectangle (1), others 0.
Grid2<std::uint8_t> OccupiedCells(const std::vector<Rectangle>& rects, const GridLimits& limits);

}  // namespace mjslam::eval::detail
