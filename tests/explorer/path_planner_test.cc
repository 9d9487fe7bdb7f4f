#include <cmath>

#include <gtest/gtest.h>

#include "common/segments.h"
#include "explorer/path_planner.h"
#include "tests/support/kinematic_sim.h"

namespace mjslam::explorer {
namespace {

using testing::Wall;

// An L-shaped corridor, 2 m wide: along x from (0, 0) to (6, 2), then up
// along y from (4, 2) to (6, 8).
std::vector<Wall> LCorridor() {
  return {{{0, 0}, {6, 0}}, {{6, 0}, {6, 8}}, {{6, 8}, {4, 8}}, {{4, 8}, {4, 2}},
          {{4, 2}, {0, 2}}, {{0, 2}, {0, 0}}};
}

OccupancyGrid MappedLCorridor() {
  OccupancyGrid grid{OccupancyGridSettings{}};
  testing::KinematicSim::Config config;
  const Pose2 views[] = {Pose2(1.0, 1.0, 0.0), Pose2(1.0, 1.0, kPi), Pose2(5.0, 1.0, 0.5 * kPi),
                         Pose2(5.0, 1.0, -0.5 * kPi), Pose2(5.0, 6.0, 0.5 * kPi),
                         Pose2(5.0, 6.0, -0.5 * kPi)};
  for (const Pose2& view : views) {
    testing::KinematicSim sim(LCorridor(), view, config);
    grid.InsertScan(sim.Scan(0.0), sim.X_WR() * config.X_RS);
  }
  return grid;
}

// The checks of a feasible path: spacing, curvature, speeds, heading
// continuity.
void ExpectFeasible(const Path& path, const ExplorerParams& params) {
  ASSERT_GE(path.size(), 2u);
  const double max_curvature = 1.0 / params.min_turn_radius_m;
  for (size_t i = 0; i < path.size(); ++i) {
    const PathPoint& p = path[i];
    EXPECT_LE(std::abs(p.curvature_per_m), max_curvature + 1e-9) << i;
    EXPECT_LE(p.speed_mps, params.cruise_speed_mps + 1e-12) << i;
    EXPECT_LE(p.speed_mps * std::abs(p.curvature_per_m),
              params.max_angular_speed_radps + 1e-9) << i;
    EXPECT_LE(p.speed_mps * p.speed_mps * std::abs(p.curvature_per_m),
              params.max_lateral_accel_mps2 + 1e-9) << i;
    if (p.turn_in_place) {
      EXPECT_EQ(p.speed_mps, 0.0) << i;
    }
    if (i == 0) continue;
    const double ds = p.s_m - path[i - 1].s_m;
    EXPECT_LE(ds, params.path_step_m + 1e-9) << i;
    // Braking: the speed can drop to the next point's within the decelerations.
    EXPECT_LE(path[i - 1].speed_mps * path[i - 1].speed_mps,
              p.speed_mps * p.speed_mps + 2.0 * params.max_linear_accel_mps2 * ds + 1e-9)
        << i;
    // The heading turns no faster than the curvature allows, except at a
    // stop-and-turn point.
    if (!path[i - 1].turn_in_place && !p.turn_in_place) {
      EXPECT_LE(std::abs(WrapAngle(p.heading_rad - path[i - 1].heading_rad)),
                max_curvature * std::max(ds, params.path_step_m) + 1e-6)
          << i;
    }
  }
  EXPECT_EQ(path.back().speed_mps, 0.0);
}

TEST(PathPlannerTest, PathAroundACornerIsFeasibleAndCollisionFree) {
  const ExplorerParams params;
  const OccupancyGrid grid = MappedLCorridor();
  const Eigen::Vector2d start(1.0, 1.0);
  const Eigen::Vector2d goal(5.0, 7.0);
  const NavigationMap map(grid, params, start);
  const Path path = PlanPath(map, params, goal, 0.0);
  ExpectFeasible(path, params);
  EXPECT_LT((path.front().p_W - start).norm(), grid.resolution());
  EXPECT_LT((path.back().p_W - goal).norm(), grid.resolution());
  // Clear of the true walls by the clearance (less one cell for the grid).
  for (const PathPoint& p : path) {
    for (const Wall& wall : LCorridor()) {
      EXPECT_GE(PointSegmentDistance(p.p_W, wall.a, wall.b), params.clearance_m - grid.resolution())
          << p.p_W.transpose();
    }
  }
  // It turns the corner with an arc, not by stopping.
  int arcs = 0;
  for (const PathPoint& p : path) arcs += p.curvature_per_m != 0.0;
  EXPECT_GT(arcs, 5);
  // Not much longer than the shortest way through the corridor centre
  // (4 + 6 m, less the rounded corner).
  EXPECT_LT(path.back().s_m, 10.5);
}

TEST(PathPlannerTest, UnreachableGoalGivesNoPath) {
  const ExplorerParams params;
  const OccupancyGrid grid = MappedLCorridor();
  const NavigationMap map(grid, params, {1.0, 1.0});
  // Beyond the wall, in unknown space.
  EXPECT_TRUE(PlanPath(map, params, {2.0, 5.0}, 0.0).empty());
  EXPECT_FALSE(std::isfinite(map.CostTo(grid.CellOf({2.0, 5.0}).x(),
                                        grid.CellOf({2.0, 5.0}).y())));
}

TEST(PathPlannerTest, RightAngleCornerIsRoundedWithTheLargestArcThatFits) {
  ExplorerParams params;
  const Path path = SmoothPolyline({{0, 0}, {3, 0}, {3, 3}}, nullptr, params);
  ExpectFeasible(path, params);
  double curvature = 0.0;
  for (const PathPoint& p : path) curvature = std::max(curvature, p.curvature_per_m);
  EXPECT_NEAR(curvature, 1.0 / params.max_turn_radius_m, 1e-12);  // left turn
  // The arc stays inside the corner: no point beyond x = 3 or below y = 0.
  for (const PathPoint& p : path) {
    EXPECT_LE(p.p_W.x(), 3.0 + 1e-9);
    EXPECT_GE(p.p_W.y(), -1e-9);
  }
}

TEST(PathPlannerTest, HairpinBecomesAStopAndTurnPoint) {
  const ExplorerParams params;
  // Back along almost the same line: no arc of 0.4 m fits in 0.1 m.
  const Path path = SmoothPolyline({{0, 0}, {2, 0}, {0, 0.1}}, nullptr, params);
  ExpectFeasible(path, params);
  int stops = 0;
  for (const PathPoint& p : path) {
    if (!p.turn_in_place) continue;
    ++stops;
    EXPECT_NEAR((p.p_W - Eigen::Vector2d(2, 0)).norm(), 0.0, 1e-12);
  }
  EXPECT_EQ(stops, 1);
}

TEST(PathPlannerTest, ClearanceIsTheDistanceToTheNearestOccupiedCell) {
  const ExplorerParams params;
  const OccupancyGrid grid = MappedLCorridor();
  const NavigationMap map(grid, params, {1.0, 1.0});
  // In the 2 m corridor, 1 m from both walls: capped at the preferred
  // clearance (0.9 m), nothing reads more.
  EXPECT_EQ(map.ClearanceAt({2.0, 1.0}), static_cast<float>(ClearanceCapM(params)));
  EXPECT_NEAR(map.ClearanceAt({2.0, 0.7}), 0.7, 1.5 * grid.resolution());
  EXPECT_NEAR(map.ClearanceAt({2.0, 0.4}), 0.4, 1.5 * grid.resolution());
  EXPECT_TRUE(map.TraversableAt({2.0, 1.0}));
  EXPECT_FALSE(map.TraversableAt({2.0, 0.3}));  // too close to the wall
}

TEST(PathPlannerTest, PathClearOfPointsDetectsAnObstacleOnThePath) {
  const ExplorerParams params;
  const Path path = SmoothPolyline({{0, 0}, {3, 0}}, nullptr, params);
  EXPECT_TRUE(PathClearOfPoints(path, 0, {{1.5, 0.5}}, 0.3));
  EXPECT_FALSE(PathClearOfPoints(path, 0, {{1.5, 0.2}}, 0.3));
  // Behind the point `from`: ignored.
  EXPECT_TRUE(PathClearOfPoints(path, 40, {{1.5, 0.2}}, 0.3));
}

}  // namespace
}  // namespace mjslam::explorer
