#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/pose2.h"

namespace mjslam::sim {

/// The footprint in the floor plane of one static obstacle of a world (a wall,
/// a pillar): the ground truth the laser sees, for tests, metrics and plots.
struct ObstacleFootprint {
  enum class Shape {
    /// An upright box: a rectangle with half extents `half_extents_m` along
    /// the x and y axes of `X_WO`.
    kRectangle,
    /// An upright cylinder or capsule, a sphere, or any other geom (by its
    /// bounding sphere, so conservatively): a disc of radius `radius_m`.
    kCircle,
  };
  Shape shape = Shape::kRectangle;
  /// The geom's name in the world file (empty if it has none).
  std::string name;
  /// Pose of the footprint's centre and axes in the world W.
  Pose2 X_WO;
  /// Rectangle half extents along its own x and y, metres (kRectangle).
  Eigen::Vector2d half_extents_m = Eigen::Vector2d::Zero();
  /// Disc radius, metres (kCircle).
  double radius_m = 0.0;
  /// Vertical extent of the obstacle, metres above the floor.
  double z_min_m = 0.0;
  double z_max_m = 0.0;
  /// True when the shape is exact (upright box, cylinder, capsule, sphere);
  /// false for a bounding-disc stand-in.
  bool exact = true;
};

/// Corners p_WC of a rectangle footprint, counter-clockwise. Precondition:
/// shape == kRectangle (checked).
std::array<Eigen::Vector2d, 4> RectangleCorners(const ObstacleFootprint& obstacle);

/// Distance in the plane from p_W to the footprint, metres (0 inside it).
double DistanceToFootprint(const Eigen::Vector2d& p_W, const ObstacleFootprint& obstacle);

/// Smallest DistanceToFootprint over `obstacles` (+infinity if empty).
double DistanceToObstacles(const Eigen::Vector2d& p_W,
                           const std::vector<ObstacleFootprint>& obstacles);

}  // namespace mjslam::sim
