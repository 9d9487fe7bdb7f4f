#pragma once

#include <vector>

#include <Eigen/Core>

namespace mjslam::eval {

/// One feature of a map as eval sees it (a filter's estimate or the ground
/// truth), in the world frame W; the same content as a row of the map CSV
/// files (docs/run_directory.md).
struct MapFeature {
  enum class Type { kLine, kCorner };
  /// Kind of a true corner as seen from the free side: concave (inside
  /// corner of a room) or convex (points into the free space). Estimated maps
  /// do not know it (kUnknown), nor do lines.
  enum class CornerKind { kUnknown, kConcave, kConvex };

  int id = 0;
  Type type = Type::kLine;
  /// Line: (r, al) with x cos(al) + y sin(al) = r, r >= 0, al in (-pi, pi]
  /// (metres, radians), the convention of slam/. Corner: (x, y), metres.
  Eigen::Vector2d params = Eigen::Vector2d::Zero();
  /// 2x2 covariance of `params` (zero for the ground truth).
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  /// Lines: the seen (estimate) or true segment p_WA to p_WB on the line.
  bool has_segment = false;
  Eigen::Vector2d p_WA = Eigen::Vector2d::Zero();
  Eigen::Vector2d p_WB = Eigen::Vector2d::Zero();
  CornerKind corner_kind = CornerKind::kUnknown;
  /// True corners: unit vector from the vertex into the free space (the
  /// bisector of the two faces' outward normals); zero otherwise.
  Eigen::Vector2d free_direction_W = Eigen::Vector2d::Zero();
};

using Map = std::vector<MapFeature>;

}  // namespace mjslam::eval
