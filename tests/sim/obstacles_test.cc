// Obstacle footprints: distances and corners in the plane (pure code).

#include <cmath>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "sim/obstacles.h"

namespace mjslam::sim {
namespace {

ObstacleFootprint Rectangle(const Pose2& X_WO, double hx, double hy) {
  ObstacleFootprint obstacle;
  obstacle.shape = ObstacleFootprint::Shape::kRectangle;
  obstacle.X_WO = X_WO;
  obstacle.half_extents_m = Eigen::Vector2d(hx, hy);
  return obstacle;
}

TEST(ObstaclesTest, DistanceToARotatedRectangle) {
  const ObstacleFootprint wall = Rectangle(Pose2(1.0, 2.0, DegToRad(90.0)), 2.0, 0.1);
  // The wall runs along y from 0 to 4 at x = 1, 0.2 m thick.
  EXPECT_NEAR(DistanceToFootprint({3.0, 2.0}, wall), 1.9, 1e-12);
  EXPECT_NEAR(DistanceToFootprint({1.0, 5.0}, wall), 1.0, 1e-12);
  EXPECT_NEAR(DistanceToFootprint({2.1, 5.0}, wall), std::hypot(1.0, 1.0), 1e-12);
  EXPECT_EQ(DistanceToFootprint({1.05, 3.0}, wall), 0.0);
}

TEST(ObstaclesTest, DistanceToACircleAndToTheNearestObstacle) {
  ObstacleFootprint pillar;
  pillar.shape = ObstacleFootprint::Shape::kCircle;
  pillar.X_WO = Pose2(0.0, 0.0, 0.0);
  pillar.radius_m = 0.3;
  EXPECT_NEAR(DistanceToFootprint({1.0, 0.0}, pillar), 0.7, 1e-12);
  EXPECT_EQ(DistanceToFootprint({0.1, 0.1}, pillar), 0.0);
  const std::vector<ObstacleFootprint> both = {pillar, Rectangle(Pose2(3, 0, 0), 0.1, 1.0)};
  EXPECT_NEAR(DistanceToObstacles({2.0, 0.0}, both), 0.9, 1e-12);
  EXPECT_TRUE(std::isinf(DistanceToObstacles({0, 0}, {})));
}

TEST(ObstaclesTest, RectangleCornersAreCounterClockwise) {
  const auto corners = RectangleCorners(Rectangle(Pose2(1.0, 1.0, DegToRad(30.0)), 1.0, 0.5));
  double twice_area = 0.0;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d& a = corners[i];
    const Eigen::Vector2d& b = corners[(i + 1) % 4];
    twice_area += a.x() * b.y() - b.x() * a.y();
  }
  EXPECT_NEAR(twice_area, 2.0 * 2.0 * 1.0, 1e-12);  // positive: counter-clockwise
}

}  // namespace
}  // namespace mjslam::sim
