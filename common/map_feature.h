#pragma once

#include <vector>

#include <Eigen/Core>

namespace mjslam {

/// The two kinds of map feature, each two numbers: a line (r, al) in polar
/// form in W (x cos al + y sin al = r, r >= 0, al wrapped), or a corner point
/// p_WC = (x, y).
enum class FeatureType { kLine, kCorner };

/// One feature of a map in the world frame W: a filter's estimate
/// (slam::EkfSlam::Map) or the ground truth (eval::BuildGroundTruthMap); the
/// same content as a row of the map CSV files (README, "The run directory").
struct MapFeature {
  /// The feature kinds: Type::kLine, Type::kCorner.
  using Type = FeatureType;
  /// Kind of a true corner as seen from the free side: concave (inside
  /// corner of a room) or convex (points into the free space). Estimated maps
  /// do not know it (kUnknown), nor do lines.
  enum class CornerKind { kUnknown, kConcave, kConvex };

  /// Stable id: in order of creation from 0 (estimates), or in map order
  /// (ground truth).
  int id = 0;
  /// Line or corner.
  Type type = Type::kLine;
  /// Line: (r, al) in canonical form (r >= 0, al in (-pi, pi]); corner:
  /// (x, y). Metres, radians.
  Eigen::Vector2d params = Eigen::Vector2d::Zero();
  /// 2x2 covariance of `params`: the marginal block of P for an estimate,
  /// zero for the ground truth.
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  /// Lines: true when p_WA, p_WB hold the seen (estimate) or true segment on
  /// the line, metres in W. False (and zero points) for corners.
  bool has_segment = false;
  Eigen::Vector2d p_WA = Eigen::Vector2d::Zero();
  Eigen::Vector2d p_WB = Eigen::Vector2d::Zero();
  /// True corners only; kUnknown otherwise.
  CornerKind corner_kind = CornerKind::kUnknown;
  /// True corners: unit vector from the vertex into the free space (the
  /// bisector of the two faces' outward normals); zero otherwise.
  Eigen::Vector2d free_direction_W = Eigen::Vector2d::Zero();
};

/// A map: its features in order.
using FeatureMap = std::vector<MapFeature>;

}  // namespace mjslam
