// The explored fraction from a world's true geometry.
#include <cmath>

#include <gtest/gtest.h>

#include "app/true_coverage.h"

namespace mjslam::app {
namespace {

sim::ObstacleFootprint Wall(double x, double y, double half_x, double half_y) {
  sim::ObstacleFootprint wall;
  wall.X_WO = Pose2(x, y, 0.0);
  wall.half_extents_m = Eigen::Vector2d(half_x, half_y);
  return wall;
}

// A 6 x 4 m room (inside) with 0.1 m walls, and a closed 1 x 1 m box inside
// it that the robot cannot enter.
std::vector<sim::ObstacleFootprint> Room() {
  return {Wall(0.0, 2.05, 3.1, 0.05), Wall(0.0, -2.05, 3.1, 0.05), Wall(3.05, 0.0, 0.05, 2.1),
          Wall(-3.05, 0.0, 0.05, 2.1),
          // the box around (2, 1): walls 0.1 m thick
          Wall(2.0, 1.55, 0.6, 0.05), Wall(2.0, 0.45, 0.6, 0.05), Wall(1.45, 1.0, 0.05, 0.6),
          Wall(2.55, 1.0, 0.05, 0.6)};
}

LaserScan FullCircle(double range) {
  LaserScan scan;
  scan.angle_min_rad = -M_PI;
  scan.angle_increment_rad = 2.0 * M_PI / 720.0;
  scan.max_range_m = 30.0;
  scan.ranges_m.assign(720, range);
  scan.has_return.assign(720, 1);
  return scan;
}

TEST(TrueCoverageTest, ReachableAreaIsTheRoomLessTheClosedBox) {
  const TrueCoverage coverage(Room(), Eigen::Vector2d(-1.0, -1.0), 0.1, 0.3);
  // 6 x 4 = 24 m^2 inside, less the box and its walls (1.2 x 1.2 = 1.44).
  // Cells whose centre is within 3 cm of a wall are not free: about a cell
  // row along each wall, so allow 10 %.
  EXPECT_GT(coverage.ReachableArea(), 0.9 * (24.0 - 1.44));
  EXPECT_LT(coverage.ReachableArea(), 24.0 - 1.44 + 1e-9);
  EXPECT_EQ(coverage.ExploredFraction(), 0.0);
}

TEST(TrueCoverageTest, BeamsMarkWhatTheyCross) {
  TrueCoverage coverage(Room(), Eigen::Vector2d(-1.0, -1.0), 0.1, 0.3);
  // A full circle of 1 m beams from (-1, -1): pi m^2 of 22.6 m^2.
  coverage.Observe(Pose2(-1.0, -1.0, 0.0), FullCircle(1.0));
  const double expected = M_PI / coverage.ReachableArea();
  EXPECT_NEAR(coverage.ExploredFraction(), expected, 0.2 * expected);
  // Seeing the same again adds nothing; seeing farther adds.
  const double once = coverage.ExploredFraction();
  coverage.Observe(Pose2(-1.0, -1.0, 0.7), FullCircle(1.0));
  EXPECT_NEAR(coverage.ExploredFraction(), once, 0.02);
  coverage.Observe(Pose2(-1.0, -1.0, 0.0), FullCircle(2.0));
  EXPECT_GT(coverage.ExploredFraction(), 2.0 * once);
}

TEST(TrueCoverageTest, TheInsideOfTheClosedBoxDoesNotCount) {
  TrueCoverage coverage(Room(), Eigen::Vector2d(-1.0, -1.0), 0.1, 0.3);
  // Beams from inside the box see only the box's inside: nothing reachable.
  coverage.Observe(Pose2(2.0, 1.0, 0.0), FullCircle(0.45));
  EXPECT_EQ(coverage.ExploredFraction(), 0.0);
}

}  // namespace
}  // namespace mjslam::app
