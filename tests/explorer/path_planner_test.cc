#include <cmath>
#include <limits>
#include <vector>

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
  OccupancyGrid grid{ExplorerParams{}};
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

// A room's wall 0.15 m thick along y in [3.25, 3.4] with a 0.85 m door at
// x in [1.875, 2.725] (the 40 x 30 m building's), mapped from both sides.
std::vector<Wall> WallWithDoor() {
  std::vector<Wall> walls = testing::Box(-1.0, 0.0, 5.0, 6.0);
  for (const Wall& wall : testing::Box(-1.0, 3.25, 1.875, 3.4)) walls.push_back(wall);
  for (const Wall& wall : testing::Box(2.725, 3.25, 5.0, 3.4)) walls.push_back(wall);
  return walls;
}

// An axle stopped in front of the door, anywhere within 0.3 m of where the
// building's robot was (a cell's centre 0.3 m before the wall, a little off
// the door's middle): its path through the door starts with the leg through
// it, not with a leg of a cell or two that turns it away first (seen as a
// robot turning left and right in front of a door for 1,400 s, each turn
// restarted by the replan: the axle never moved, h swung past the short
// leg's end). Every path from those starts: no stop-and-turn point after the
// first within 0.2 m of the axle's cell (the tracker takes one within 0.1 m
// of h as reached), and the path starts within 0.2 m of the axle.
TEST(PathPlannerTest, PathThroughADoorDoesNotStartWithATinyLeg) {
  const ExplorerParams params;
  const std::vector<Wall> walls = WallWithDoor();
  OccupancyGrid grid{ExplorerParams{}};
  testing::KinematicSim::Config config;
  config.max_range_m = 10.0;
  for (const Pose2& view : {Pose2(2.3, 1.5, 0.5 * kPi), Pose2(2.3, 1.5, -0.5 * kPi),
                            Pose2(2.3, 5.0, 0.5 * kPi), Pose2(2.3, 5.0, -0.5 * kPi),
                            Pose2(2.3, 2.9, 0.5 * kPi)}) {
    testing::KinematicSim sim(walls, view, config);
    grid.InsertScan(sim.Scan(0.0), sim.X_WR() * config.X_RS);
  }
  const Eigen::Vector2d goal(3.475, 5.375);
  int tiny = 0;
  int plans = 0;
  for (double dx = -0.3; dx <= 0.3 + 1e-9; dx += 0.025) {
    for (double dy = -0.3; dy <= 0.0 + 1e-9; dy += 0.025) {
      const Eigen::Vector2d start(2.375 + dx, 2.975 + dy);
      const NavigationMap map(grid, params, start);
      const Path path = PlanPath(map, params, goal, 0.5 * kPi);
      if (path.empty()) continue;
      ++plans;
      EXPECT_LT((path.front().p_W - start).norm(), 0.2);
      for (size_t i = 1; i < path.size(); ++i) {
        const Eigen::Vector2i cell = grid.CellOf(start);
        const Eigen::Vector2d start_cell = grid.CellCenter(cell.x(), cell.y());
        const double from_start_m = (path[i].p_W - start_cell).norm();
        if (path[i].turn_in_place && from_start_m < 0.2 - 1e-9) {
          ++tiny;
          ADD_FAILURE() << "start (" << start.x() << ", " << start.y() << "): a stop "
                        << from_start_m << " m away";
          break;
        }
      }
    }
  }
  EXPECT_GE(plans, 100);
  EXPECT_EQ(tiny, 0);
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

// A straight corridor 2 m wide from x = 0 to x = length_m, mapped by scans
// (4 m laser) every 1 m along its middle, looking both ways.
OccupancyGrid MappedCorridor(double length_m) {
  const std::vector<Wall> walls = {{{0, 0}, {length_m, 0}},
                                   {{length_m, 0}, {length_m, 2}},
                                   {{length_m, 2}, {0, 2}},
                                   {{0, 2}, {0, 0}}};
  OccupancyGrid grid{ExplorerParams{}};
  testing::KinematicSim::Config config;
  for (double x = 1.0; x < length_m; x += 1.0) {
    for (const double heading : {0.0, kPi}) {
      testing::KinematicSim sim(walls, Pose2(x, 1.0, heading), config);
      grid.InsertScan(sim.Scan(0.0), sim.X_WR() * config.X_RS);
    }
  }
  return grid;
}

TEST(NavigationMapTest, SearchesOnDemandGiveTheCostsOfTheWholeSearch) {
  const ExplorerParams params;
  const OccupancyGrid grid = MappedLCorridor();
  const Eigen::Vector2d start(1.0, 1.0);
  const NavigationMap full(grid, params, start);
  // Dijkstra to a cost bound: exactly the cells the whole search costs at
  // most that much, with the same costs.
  NavigationMap bounded(grid, params, start, NavigationMap::Search::kOnDemand);
  bounded.ExpandTo(3.0);
  EXPECT_EQ(bounded.expanded_cost(), 3.0);
  int inside = 0;
  for (int iy = 0; iy < grid.height(); ++iy) {
    for (int ix = 0; ix < grid.width(); ++ix) {
      const double cost = full.CostTo(ix, iy);
      if (cost <= 3.0) {
        ++inside;
        EXPECT_EQ(bounded.CostTo(ix, iy), cost) << ix << " " << iy;
      } else {
        EXPECT_FALSE(std::isfinite(bounded.CostTo(ix, iy))) << ix << " " << iy;
      }
    }
  }
  EXPECT_EQ(bounded.settled_cells(), inside);
  EXPECT_GT(full.settled_cells(), 2 * inside);
  // Resumed to the end: every cost of the whole search.
  bounded.ExpandTo(std::numeric_limits<double>::infinity());
  EXPECT_FALSE(std::isfinite(bounded.expanded_cost()));
  EXPECT_EQ(bounded.settled_cells(), full.settled_cells());
  // A* to single goals: the least cost, and a path of 8-neighbours that
  // reaches the goal.
  for (const Eigen::Vector2d& goal_W :
       {Eigen::Vector2d(5.0, 7.0), Eigen::Vector2d(3.0, 1.5), Eigen::Vector2d(5.5, 3.0)}) {
    const Eigen::Vector2i goal = grid.CellOf(goal_W);
    NavigationMap astar(grid, params, start, NavigationMap::Search::kOnDemand);
    ASSERT_TRUE(astar.SearchTo(goal));
    EXPECT_NEAR(astar.CostTo(goal.x(), goal.y()), full.CostTo(goal.x(), goal.y()),
                1e-5 * full.CostTo(goal.x(), goal.y()));
    EXPECT_LT(astar.settled_cells(), full.settled_cells());
    const std::vector<Eigen::Vector2i> cells = astar.CellPath(goal);
    ASSERT_FALSE(cells.empty());
    EXPECT_EQ(cells.front(), grid.CellOf(start));
    EXPECT_EQ(cells.back(), goal);
    for (size_t i = 1; i < cells.size(); ++i) {
      EXPECT_LE((cells[i] - cells[i - 1]).cwiseAbs().maxCoeff(), 1);
      EXPECT_TRUE(astar.Traversable(cells[i].x(), cells[i].y()));
    }
  }
  // An unreachable goal (in the wall): no path.
  NavigationMap astar(grid, params, start, NavigationMap::Search::kOnDemand);
  EXPECT_FALSE(astar.SearchTo(grid.CellOf(Eigen::Vector2d(6.0, 4.0))));
}

TEST(NavigationMapTest, MapsThatReuseATableSeeNothingOfEachOther) {
  // Maps from two starts, side by side (each with its own table), then in
  // turn (each taking the table the last one gave back): every map sees
  // only its own search, with the same costs.
  const ExplorerParams params;
  const OccupancyGrid grid = MappedLCorridor();
  const std::vector<Eigen::Vector2d> starts = {{1.0, 1.0}, {5.0, 7.0}};
  std::vector<std::vector<double>> costs(starts.size());
  {
    const NavigationMap a(grid, params, starts[0]);
    const NavigationMap b(grid, params, starts[1]);
    for (int iy = 0; iy < grid.height(); ++iy) {
      for (int ix = 0; ix < grid.width(); ++ix) {
        costs[0].push_back(a.CostTo(ix, iy));
        costs[1].push_back(b.CostTo(ix, iy));
      }
    }
  }
  ASSERT_NE(costs[0], costs[1]);
  for (int round = 0; round < 3; ++round) {
    for (size_t k = 0; k < starts.size(); ++k) {
      NavigationMap map(grid, params, starts[k], NavigationMap::Search::kOnDemand);
      int finite = 0;
      for (int iy = 0; iy < grid.height(); ++iy) {
        for (int ix = 0; ix < grid.width(); ++ix) finite += std::isfinite(map.CostTo(ix, iy));
      }
      EXPECT_EQ(finite, 0) << "round " << round << " start " << k;
      map.ExpandTo(std::numeric_limits<double>::infinity());
      std::vector<double> got;
      for (int iy = 0; iy < grid.height(); ++iy) {
        for (int ix = 0; ix < grid.width(); ++ix) got.push_back(map.CostTo(ix, iy));
      }
      EXPECT_EQ(got, costs[k]) << "round " << round << " start " << k;
    }
  }
}

TEST(NavigationMapTest, SearchCostDoesNotGrowWithTheMappedArea) {
  // The same start and goal, 4 m apart, in corridors of 10 m and 40 m: the
  // searches on demand settle the same cells, the whole search four times
  // as many.
  const ExplorerParams params;
  const Eigen::Vector2d start(1.0, 1.0);
  const Eigen::Vector2i goal_offset(80, 0);
  std::vector<int> astar_cells;
  std::vector<int> bounded_cells;
  std::vector<int> full_cells;
  for (const double length_m : {10.0, 40.0}) {
    const OccupancyGrid grid = MappedCorridor(length_m);
    NavigationMap astar(grid, params, start, NavigationMap::Search::kOnDemand);
    ASSERT_TRUE(astar.SearchTo(grid.CellOf(start) + goal_offset));
    astar_cells.push_back(astar.settled_cells());
    NavigationMap bounded(grid, params, start, NavigationMap::Search::kOnDemand);
    bounded.ExpandTo(6.0);
    bounded_cells.push_back(bounded.settled_cells());
    const NavigationMap full(grid, params, start);
    full_cells.push_back(full.settled_cells());
  }
  EXPECT_EQ(astar_cells[0], astar_cells[1]);
  EXPECT_EQ(bounded_cells[0], bounded_cells[1]);
  EXPECT_GT(full_cells[1], 3 * full_cells[0]);
  EXPECT_LT(astar_cells[1], full_cells[0]);
}

}  // namespace
}  // namespace mjslam::explorer
