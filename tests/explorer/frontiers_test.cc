#include <cmath>

#include <gtest/gtest.h>

#include "explorer/frontiers.h"
#include "tests/support/kinematic_sim.h"

namespace mjslam::explorer {
namespace {

LaserScan ScanOfRanges(const std::vector<double>& ranges, const std::vector<std::uint8_t>& echo) {
  LaserScan scan;
  scan.angle_min_rad = -0.5 * kPi;
  scan.angle_increment_rad = kPi / (ranges.size() - 1);
  scan.max_range_m = 30.0;
  scan.ranges_m = ranges;
  scan.has_return = echo;
  for (size_t i = 0; i < ranges.size(); ++i) {
    if (!echo[i]) scan.ranges_m[i] = 30.0;
  }
  return scan;
}

TEST(FrontiersTest, OpeningBetweenEchoesGivesAPointInFront) {
  // A wall at 2 m with a deep gap from beam 95 to 105 (5 deg left of ahead
  // to 15 deg left).
  std::vector<double> ranges(181, 2.0);
  for (int i = 95; i <= 105; ++i) ranges[i] = 6.0;
  const ExplorerParams params;
  const std::vector<Eigen::Vector2d> points =
      LocalFrontierPoints(ScanOfRanges(ranges, std::vector<std::uint8_t>(181, 1)),
                          Pose2(0.0, 0.0, 0.0), params);
  ASSERT_EQ(points.size(), 2u);  // both edges of the gap
  for (const Eigen::Vector2d& p : points) {
    const double bearing = std::atan2(p.y(), p.x());
    EXPECT_GT(bearing, DegToRad(3.0));
    EXPECT_LT(bearing, DegToRad(17.0));
    // Halfway between the 2 m and 6 m echoes, 0.4 m back toward the laser.
    EXPECT_NEAR(p.norm(), 4.0 - params.frontier_standoff_m, 0.05);
  }
}

TEST(FrontiersTest, SmallStepsAndNarrowGapsAreNotOpenings) {
  std::vector<double> ranges(181);
  for (int i = 0; i < 181; ++i) ranges[i] = 2.0 + 0.01 * (i % 7);  // rough wall
  std::vector<std::uint8_t> echo(181, 1);
  echo[90] = 0;  // one no-return beam: 7 cm wide at 4 m
  EXPECT_TRUE(LocalFrontierPoints(ScanOfRanges(ranges, echo), Pose2(), ExplorerParams{})
                  .empty());
}

TEST(FrontiersTest, RunOfNoReturnBeamsGivesAPointOnItsMiddleBeam) {
  std::vector<double> ranges(181, 2.0);
  std::vector<std::uint8_t> echo(181, 1);
  for (int i = 80; i <= 100; ++i) echo[i] = 0;  // 21 deg: 1.5 m wide at 4 m
  const ExplorerParams params;
  const Pose2 X_WS(1.0, 2.0, 0.5 * kPi);
  const std::vector<Eigen::Vector2d> points =
      LocalFrontierPoints(ScanOfRanges(ranges, echo), X_WS, params);
  // The run's edges: echo at 2 m next to an open beam are not echo pairs;
  // the run itself gives one point on beam 90 (straight ahead, +y in W).
  ASSERT_EQ(points.size(), 1u);
  const double d = params.no_return_free_range_m - params.frontier_standoff_m;
  EXPECT_NEAR(points[0].x(), 1.0, 1e-9);
  EXPECT_NEAR(points[0].y(), 2.0 + d, 1e-9);
}

// Grid of a corridor [0, 8] x [0, 2] open at x = 8, seen from x = 1 facing
// +x with a 4 m laser.
OccupancyGrid CorridorGrid() {
  std::vector<testing::Wall> walls = {{{0, 0}, {8, 0}}, {{0, 2}, {8, 2}}, {{0, 0}, {0, 2}}};
  testing::KinematicSim::Config config;
  config.max_range_m = 4.0;
  OccupancyGrid grid{OccupancyGridSettings{}};
  for (const double th : {0.0, kPi}) {
    testing::KinematicSim sim(walls, Pose2(1.5, 1.0, th), config);
    grid.InsertScan(sim.Scan(0.0), sim.X_WR() * config.X_RS);
  }
  return grid;
}

TEST(FrontiersTest, GlobalFrontierIsAtTheEndOfWhatWasSeen) {
  const OccupancyGrid grid = CorridorGrid();
  const ExplorerParams params;
  const std::vector<Eigen::Vector2d> points = GlobalFrontierPoints(grid, params);
  ASSERT_FALSE(points.empty());
  // Every frontier with gain is at the far end of the seen part (x about
  // 1.4 + 4 m), none inside the corridor behind.
  int with_gain = 0;
  for (const Eigen::Vector2d& p : points) {
    const double gain = InformationGain(grid, p, params.gain_radius_m);
    if (gain < params.min_gain_m2) continue;
    ++with_gain;
    EXPECT_GT(p.x(), 4.5) << p.transpose();
    EXPECT_GT(p.y(), 0.0);
    EXPECT_LT(p.y(), 2.0);
  }
  EXPECT_GE(with_gain, 1);
}

TEST(FrontiersTest, GainIsLargeAtTheOpenEndAndSmallInsideTheSeenPart) {
  const OccupancyGrid grid = CorridorGrid();
  const ExplorerParams params;
  EXPECT_GT(InformationGain(grid, {5.3, 1.0}, params.gain_radius_m), 1.0);
  EXPECT_LT(InformationGain(grid, {2.0, 1.0}, params.gain_radius_m), params.min_gain_m2);
}

}  // namespace
}  // namespace mjslam::explorer
