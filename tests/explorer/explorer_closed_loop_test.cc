// Closed loop of the explorer in the test-only kinematic simulator: two rooms
// joined by a door, a column in the second room. The explorer must see at
// least 95 % of the reachable free area without touching a wall and end with
// a reason. Exact scans and the true pose: the explorer alone is under test.

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "explorer/explorer.h"
#include "tests/support/kinematic_sim.h"
#include "tests/support/seen_area.h"

namespace mjslam::explorer {
namespace {

using testing::Box;
using testing::KinematicSim;
using testing::Wall;

// The layout: rooms [0, 5] x [0, 4] and [5, 10] x [0, 4], a wall at x = 5
// with a 1.2 m door at y in [2.4, 3.6], a 0.6 m column in the second room.
std::vector<Wall> TwoRooms(double door_width_m = 1.2) {
  std::vector<Wall> walls = Box(0.0, 0.0, 10.0, 4.0);
  walls.push_back({{5.0, 0.0}, {5.0, 3.0 - 0.5 * door_width_m}});
  walls.push_back({{5.0, 3.0 + 0.5 * door_width_m}, {5.0, 4.0}});
  for (const Wall& wall : Box(7.2, 1.2, 7.8, 1.8)) walls.push_back(wall);
  return walls;
}

struct EpisodeResult {
  double t_s = 0.0;
  double explored = 0.0;
  int contacts = 0;
  bool finished = false;
  std::string reason;
  double distance_m = 0.0;
  std::vector<double> commands;
  // Positions of h at every step.
  std::vector<Eigen::Vector2d> positions_W;
};

// Runs the explorer from `X_WR0` among `walls` for at most `duration_s`;
// the seen fraction is of the area reachable in `seen_walls`.
EpisodeResult RunEpisodeIn(const std::vector<Wall>& walls, const std::vector<Wall>& seen_walls,
                           const Pose2& X_WR0, double duration_s,
                           double laser_range_m = 4.0) {
  KinematicSim::Config config;
  config.max_range_m = laser_range_m;
  KinematicSim sim(walls, X_WR0, config);
  Explorer explorer(ExplorerParams{}, config.a_m);
  testing::SeenArea seen(seen_walls, X_WR0.translation());
  EpisodeResult result;
  const double dt = 0.1;
  for (double t = 0.0; t < duration_s; t += dt) {
    const LaserScan scan = sim.Scan(t);
    seen.Add(scan, sim.X_WR() * config.X_RS);
    const ExplorerOutput out = explorer.Step(sim.X_WR(), &scan, config.X_RS, t, dt);
    result.commands.push_back(out.command.v_mps);
    result.commands.push_back(out.command.w_radps);
    result.positions_W.push_back(sim.X_WR().translation());
    if (out.finished) {
      result.finished = true;
      result.reason = out.finish_reason;
      result.t_s = t;
      break;
    }
    sim.Step(out.command, dt);
    result.t_s = t;
  }
  result.explored = seen.Fraction();
  result.contacts = sim.contacts();
  result.distance_m = sim.distance_m();
  return result;
}

EpisodeResult RunEpisode(const Pose2& X_WR0, double duration_s, double door_width_m = 1.2) {
  return RunEpisodeIn(TwoRooms(door_width_m), TwoRooms(), X_WR0, duration_s);
}

// From two start poses (one in the first room facing a wall 1 m ahead, one
// next to the door in the second room): explored >= 95 %, no contact,
// `no_frontier`, within 10 minutes of simulated time.
TEST(ExplorerClosedLoopTest, ExploresTwoRoomsWithoutContact) {
  const Pose2 starts[] = {Pose2(4.0, 2.0, 0.0), Pose2(6.2, 2.5, -0.5)};
  for (const Pose2& start : starts) {
    const EpisodeResult result = RunEpisode(start, 600.0);
    std::printf("start (%.1f, %.1f, %.2f): finished %d (%s) at t = %.1f s, explored %.3f, "
                "distance %.1f m, contacts %d\n",
                start.x, start.y, start.theta, result.finished, result.reason.c_str(),
                result.t_s, result.explored, result.distance_m, result.contacts);
    EXPECT_TRUE(result.finished);
    EXPECT_EQ(result.reason, "no_frontier");
    EXPECT_GE(result.explored, 0.95);
    EXPECT_EQ(result.contacts, 0);
  }
}

TEST(ExplorerClosedLoopTest, GetsFreeWhenWedgedNextToTheDoorWall) {
  // Just through the door, heading -54 deg, the rear right corner 8 cm from
  // the door wall below the jamb (office, seed 3: wedged in a doorway). The
  // initial turn (to the left) and backing up would both touch the wall;
  // only driving forward is safe. The recovery must find it, instead of
  // holding the robot still for good.
  const EpisodeResult result = RunEpisode(Pose2(5.51, 1.93, DegToRad(-54.0)), 300.0);
  std::printf("wedged start: %s after %.1f s, %.1f %% seen, %d contacts\n",
              result.reason.c_str(), result.t_s, 100.0 * result.explored, result.contacts);
  EXPECT_TRUE(result.finished);
  EXPECT_EQ(result.reason, "no_frontier");
  EXPECT_GE(result.explored, 0.95);
  EXPECT_EQ(result.contacts, 0);
}

// A door too narrow for the robot (0.55 m: the wheels make it 0.525 m wide
// and paths keep 0.32 m clearance): the explorer explores its own room, does
// not circle in front of the door, and ends with `unreachable` well before
// the time limit.
TEST(ExplorerClosedLoopTest, EndsUnreachableBehindANarrowDoor) {
  const EpisodeResult result = RunEpisode(Pose2(1.5, 1.0, 0.3), 600.0, 0.55);
  std::printf("narrow door: finished %d (%s) at t = %.1f s, explored %.3f, contacts %d\n",
              result.finished, result.reason.c_str(), result.t_s, result.explored,
              result.contacts);
  EXPECT_TRUE(result.finished);
  EXPECT_EQ(result.reason, "unreachable");
  EXPECT_LT(result.t_s, 300.0);
  EXPECT_EQ(result.contacts, 0);
  // The first room (half the area) is seen, and some of the second
  // through the door.
  EXPECT_GT(result.explored, 0.5);
}

// A corridor of 10 x 1.6 m with a room of 4 x 4 m above it, entered by a
// door of `door_width_m` (thin walls) in the middle of the corridor's wall;
// a partition across the room from its left wall (y = 3.8, x in [3, 5.2])
// hides the room's far left part from the door.
std::vector<Wall> CorridorAndRoom(double door_width_m) {
  std::vector<Wall> walls = {
      {{0.0, 0.0}, {10.0, 0.0}},
      {{0.0, 0.0}, {0.0, 1.6}},
      {{10.0, 0.0}, {10.0, 1.6}},
      {{0.0, 1.6}, {5.0 - 0.5 * door_width_m, 1.6}},
      {{5.0 + 0.5 * door_width_m, 1.6}, {10.0, 1.6}},
  };
  for (const Wall& wall : Box(3.0, 1.6, 7.0, 5.6)) {
    if (wall.a.y() != 1.6 || wall.b.y() != 1.6) walls.push_back(wall);
  }
  walls.push_back({{3.0, 3.8}, {5.2, 3.8}});
  return walls;
}

// Standard doors: the robot starts at the end of the corridor, facing away
// from the door; the only unexplored space is the room behind a 0.8 m (and a
// 0.9 m) door. It must enter the room (its whole body, 0.47 m behind h, past
// the door), see at least 99 % of the reachable area (behind the partition
// too) and end `no_frontier`, without a contact.
TEST(ExplorerClosedLoopTest, EntersARoomThroughAStandardDoor) {
  for (const double door_width_m : {0.8, 0.9}) {
    const std::vector<Wall> walls = CorridorAndRoom(door_width_m);
    const EpisodeResult result = RunEpisodeIn(walls, walls, Pose2(1.0, 0.8, kPi), 400.0);
    double deepest_y = 0.0;
    for (const Eigen::Vector2d& p : result.positions_W) deepest_y = std::max(deepest_y, p.y());
    std::printf("door %.2f m: %s after %.1f s, %.1f %% seen, deepest y %.2f m, %d contacts\n",
                door_width_m, result.reason.c_str(), result.t_s, 100.0 * result.explored,
                deepest_y, result.contacts);
    EXPECT_TRUE(result.finished);
    EXPECT_EQ(result.reason, "no_frontier");
    EXPECT_GE(deepest_y, 1.6 + 0.5);
    EXPECT_GE(result.explored, 0.99);
    EXPECT_EQ(result.contacts, 0);
  }
}

// A hall of 4 x 4 m with a dead-end strip 0.7 m wide and 6 m long leaving
// its bottom right corner to the east (y in [0, 0.7], x in [4, 10]), as
// behind the south rooms of a generated floor: the axle cannot turn in the
// strip (0.35 m of clearance in its middle), and the laser sees along it
// only from the hall's bottom 0.7 m, facing east.
std::vector<Wall> HallWithStrip() {
  return {
      {{0.0, 0.0}, {10.0, 0.0}}, {{10.0, 0.0}, {10.0, 0.7}}, {{4.0, 0.7}, {10.0, 0.7}},
      {{4.0, 0.7}, {4.0, 4.0}},  {{0.0, 4.0}, {4.0, 4.0}},   {{0.0, 0.0}, {0.0, 4.0}},
  };
}

// The strip is seen (it is a fifth of the reachable area). 10 m laser, as
// the strip's far end is 6 m from its mouth. At commit c5681d6 the second
// start saw 87 % and ended `unreachable`: the strip's frontier points were
// near the goal reached at its mouth, or had their only viewpoint there.
// What this test guards is the retry from a viewpoint away from the goals
// tried (the second look); it passes with the arrival turn off
// (face_frontier_deg 180) and with max_view_distance_m 0.8, which the
// generated floor's strip needs (docs/results.md).
TEST(ExplorerClosedLoopTest, SeesADeadEndStripTooNarrowToTurnIn) {
  const std::vector<Wall> walls = HallWithStrip();
  for (const Pose2& start : {Pose2(1.0, 3.0, kPi), Pose2(2.0, 2.0, 0.5 * kPi)}) {
    const EpisodeResult result = RunEpisodeIn(walls, walls, start, 300.0, 10.0);
    std::printf("strip, start (%.1f, %.1f): %s after %.1f s, %.1f %% seen, %d contacts\n",
                start.x, start.y, result.reason.c_str(), result.t_s, 100.0 * result.explored,
                result.contacts);
    EXPECT_TRUE(result.finished);
    EXPECT_GE(result.explored, 0.99);
    EXPECT_EQ(result.contacts, 0);
  }
}

// A hall of 4 x 4 m with a dead-end strip 0.65 m wide and 4 m long leaving
// the middle of its east wall (y in [1.675, 2.325], x in [4, 8]): the axle
// cannot turn anywhere in the strip.
std::vector<Wall> HallWithMiddleStrip() {
  return {
      {{0.0, 0.0}, {4.0, 0.0}},     {{4.0, 0.0}, {4.0, 1.675}},   {{4.0, 1.675}, {8.0, 1.675}},
      {{8.0, 1.675}, {8.0, 2.325}}, {{4.0, 2.325}, {8.0, 2.325}}, {{4.0, 2.325}, {4.0, 4.0}},
      {{0.0, 4.0}, {4.0, 4.0}},     {{0.0, 0.0}, {0.0, 4.0}},
  };
}

// A robot deep in a strip too narrow to turn in, 6 deg off its axis (as one
// that tried to turn there), with the rest of the hall unexplored behind it:
// it must back out along the way it came (backing straight, the rear runs
// into the strip's wall within a metre) to where it can turn, and explore
// the hall. The robot is driven in by fixed commands while the explorer
// only maps (its commands are not applied: straight in at 0.3 m/s, axle
// from x = 2.5 to 6.1 m on the strip's axis, then a turn in place of 6 deg);
// then the explorer drives.
TEST(ExplorerClosedLoopTest, BacksOutOfADeadEndStripAlongTheWayItCame) {
  const std::vector<Wall> walls = HallWithMiddleStrip();
  KinematicSim::Config config;
  config.max_range_m = 10.0;
  const Pose2 start(2.5 + config.a_m, 2.0, 0.0);
  KinematicSim sim(walls, start, config);
  ExplorerParams params;
  params.initial_turn_deg = 0.0;
  Explorer explorer(params, config.a_m);
  testing::SeenArea seen(walls, start.translation());
  const double dt = 0.1;
  double t = 0.0;
  auto step = [&](const Twist2* fixed) {
    const LaserScan scan = sim.Scan(t);
    seen.Add(scan, sim.X_WR() * config.X_RS);
    const ExplorerOutput out = explorer.Step(sim.X_WR(), &scan, config.X_RS, t, dt);
    sim.Step(fixed != nullptr ? *fixed : out.command, dt);
    t += dt;
    return out;
  };
  const Twist2 drive_in{0.3, 0.0};
  for (int k = 0; k < 120; ++k) step(&drive_in);
  const Twist2 turn{0.0, DegToRad(6.0) / 0.5};
  for (int k = 0; k < 5; ++k) step(&turn);
  ASSERT_GT(sim.X_WR().x, 6.0);
  ASSERT_NEAR(sim.X_WR().theta, DegToRad(6.0), 1e-9);
  ASSERT_FALSE(explorer.finished());
  ASSERT_EQ(sim.contacts(), 0);
  // The explorer drives from here.
  double least_x = sim.X_WR().x;
  ExplorerOutput out;
  while (t < 400.0 && !out.finished) {
    out = step(nullptr);
    least_x = std::min(least_x, sim.X_WR().x);
  }
  std::printf("strip 0.65 m: %s after %.1f s, %.1f %% seen, least x of h %.2f m, %d contacts\n",
              out.finish_reason.c_str(), t, 100.0 * seen.Fraction(), least_x, sim.contacts());
  EXPECT_TRUE(out.finished);
  // The axle (a behind h) got back to where it can turn: 0.4 m from the
  // hall's east wall.
  EXPECT_LT(least_x - config.a_m, 4.0 - params.turn_clearance_m);
  EXPECT_GE(seen.Fraction(), 0.99);
  EXPECT_EQ(sim.contacts(), 0);
}

// Every goal sees its frontier point: no wall crosses the segment from the
// goal (the axle's cell) to the point (a goal behind a wall would be
// reached and see nothing). In the corridor and room of the standard doors
// and in the hall with the strip, exact walls, every goal of an episode.
TEST(ExplorerClosedLoopTest, EveryGoalSeesItsFrontierPoint) {
  for (const std::vector<Wall>& walls : {CorridorAndRoom(0.8), HallWithStrip()}) {
    KinematicSim::Config config;
    config.max_range_m = 10.0;
    KinematicSim sim(walls, Pose2(1.0, 0.8, kPi), config);
    Explorer explorer(ExplorerParams{}, config.a_m);
    int goals = 0;
    std::optional<Eigen::Vector2d> last_goal;
    for (double t = 0.0; t < 200.0; t += 0.1) {
      const LaserScan scan = sim.Scan(t);
      const ExplorerOutput out = explorer.Step(sim.X_WR(), &scan, config.X_RS, t, 0.1);
      if (out.finished) break;
      const std::optional<Eigen::Vector2d> goal = explorer.goal();
      if (goal && (!last_goal || *goal != *last_goal)) {
        ++goals;
        const Eigen::Vector2d to = *explorer.goal_frontier() - *goal;
        // 5 cm: the point's cell may touch a wall.
        EXPECT_GE(testing::CastRay(walls, *goal, to.normalized()), to.norm() - 0.05)
            << "goal (" << goal->x() << ", " << goal->y() << ") at t = " << t;
      }
      last_goal = goal;
      sim.Step(out.command, 0.1);
    }
    EXPECT_GE(goals, 3);
  }
}

// The log rows follow the explorer's state: frontier points, the goal, the
// path in order, and the version changes when they do.
TEST(ExplorerClosedLoopTest, LogRowsDescribeTheCurrentSet) {
  KinematicSim::Config config;
  KinematicSim sim(TwoRooms(), Pose2(1.5, 1.0, 0.3), config);
  ExplorerParams params;
  params.initial_turn_deg = 0.0;
  Explorer explorer(params, config.a_m);
  const LaserScan scan = sim.Scan(0.0);
  const int version = explorer.log_version();
  explorer.Step(sim.X_WR(), &scan, config.X_RS, 0.0, 0.1);
  EXPECT_NE(explorer.log_version(), version);
  ASSERT_TRUE(explorer.goal().has_value());
  const std::vector<ExplorerLogRow> rows = explorer.LogRows();
  int frontiers = 0;
  int goals = 0;
  int path_points = 0;
  for (const ExplorerLogRow& row : rows) {
    const std::string kind = row.kind;
    if (kind == "frontier") {
      EXPECT_EQ(row.index, frontiers);
      ++frontiers;
    }
    if (kind == "goal") {
      ++goals;
      EXPECT_EQ(row.x_m, explorer.goal()->x());
      EXPECT_EQ(row.y_m, explorer.goal()->y());
    }
    if (kind == "path") {
      EXPECT_EQ(row.index, path_points);
      EXPECT_EQ(row.x_m, explorer.path()[path_points].p_W.x());
      ++path_points;
    }
  }
  EXPECT_EQ(frontiers, static_cast<int>(explorer.frontier_points().size()));
  EXPECT_GE(frontiers, 1);
  EXPECT_EQ(goals, 1);
  EXPECT_EQ(path_points, static_cast<int>(explorer.path().size()));
  EXPECT_EQ(static_cast<int>(rows.size()), frontiers + goals + path_points);
}

// Same inputs, same commands, bit for bit.
TEST(ExplorerClosedLoopTest, EpisodeIsDeterministic) {
  const EpisodeResult first = RunEpisode(Pose2(1.5, 1.0, 0.3), 30.0);
  const EpisodeResult second = RunEpisode(Pose2(1.5, 1.0, 0.3), 30.0);
  ASSERT_EQ(first.commands.size(), second.commands.size());
  for (size_t i = 0; i < first.commands.size(); ++i) {
    ASSERT_EQ(first.commands[i], second.commands[i]) << "command value " << i;
  }
}

}  // namespace
}  // namespace mjslam::explorer
