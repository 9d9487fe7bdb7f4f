// The explored fraction from a world's true geometry.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "app/engine/true_coverage.h"

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

TEST(TrueCoverageTest, ClearanceGridIsExactUpToTheCutoff) {
  // Boxes at random yaw and discs (seed 5), some overlapping, some long.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> position(-8.0, 8.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<sim::ObstacleFootprint> obstacles;
  for (int k = 0; k < 80; ++k) {
    sim::ObstacleFootprint o;
    o.X_WO = Pose2(position(rng), position(rng), 3.0 * position(rng));
    if (k % 4 == 0) {
      o.shape = sim::ObstacleFootprint::Shape::kCircle;
      o.radius_m = 0.05 + 0.3 * unit(rng);
    } else {
      o.half_extents_m = Eigen::Vector2d(k % 9 == 0 ? 6.0 : 0.05 + unit(rng), 0.05 + 0.2 * unit(rng));
    }
    obstacles.push_back(o);
  }
  const GridLimits limits(Eigen::Vector2d(-10.0, -10.0), 0.1, 200, 200);
  const double cutoff = 0.4;
  const Grid2<double> clearance = ClearanceGrid(obstacles, limits, cutoff);
  int wrong = 0;
  int near = 0;
  for (int j = 0; j < limits.height(); ++j) {
    for (int i = 0; i < limits.width(); ++i) {
      const double exact = sim::DistanceToObstacles(limits.CellCenter(i, j), obstacles);
      if (exact <= cutoff) {
        ++near;
        wrong += clearance(i, j) != exact;
      } else {
        wrong += !(clearance(i, j) > cutoff);
      }
    }
  }
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(near, 1000);  // the test covers many cells near obstacles
}

}  // namespace
}  // namespace mjslam::app
