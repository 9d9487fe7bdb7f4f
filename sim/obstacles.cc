#include "sim/obstacles.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/check.h"

namespace mjslam::sim {

std::array<Eigen::Vector2d, 4> RectangleCorners(const ObstacleFootprint& obstacle) {
  MJSLAM_CHECK(obstacle.shape == ObstacleFootprint::Shape::kRectangle);
  const double hx = obstacle.half_extents_m.x();
  const double hy = obstacle.half_extents_m.y();
  return {obstacle.X_WO * Eigen::Vector2d(hx, hy), obstacle.X_WO * Eigen::Vector2d(-hx, hy),
          obstacle.X_WO * Eigen::Vector2d(-hx, -hy), obstacle.X_WO * Eigen::Vector2d(hx, -hy)};
}

double DistanceToFootprint(const Eigen::Vector2d& p_W, const ObstacleFootprint& obstacle) {
  // The point in the footprint's own frame O.
  const Eigen::Vector2d p_O = obstacle.X_WO.Inverse() * p_W;
  if (obstacle.shape == ObstacleFootprint::Shape::kCircle) {
    return std::max(0.0, p_O.norm() - obstacle.radius_m);
  }
  // Rectangle: distance to the box [-h, h] (0 inside).
  const double dx = std::max(0.0, std::abs(p_O.x()) - obstacle.half_extents_m.x());
  const double dy = std::max(0.0, std::abs(p_O.y()) - obstacle.half_extents_m.y());
  return std::hypot(dx, dy);
}

double DistanceToObstacles(const Eigen::Vector2d& p_W,
                           const std::vector<ObstacleFootprint>& obstacles) {
  double distance = std::numeric_limits<double>::infinity();
  for (const ObstacleFootprint& obstacle : obstacles) {
    distance = std::min(distance, DistanceToFootprint(p_W, obstacle));
  }
  return distance;
}

}  // namespace mjslam::sim
