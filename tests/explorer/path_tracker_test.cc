#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "explorer/explorer.h"
#include "explorer/path_tracker.h"
#include "tests/support/kinematic_sim.h"

namespace mjslam::explorer {
namespace {

double DistanceToPath(const Path& path, const Eigen::Vector2d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const PathPoint& q : path) best = std::min(best, (q.p_W - p).norm());
  return best;
}

// Follows `path` from `start` in an empty world; returns the largest
// distance of h from the path after the first `settle_m` travelled.
double Follow(const Path& path, const Pose2& start, double settle_m, bool* done,
              const ExplorerParams& params) {
  testing::KinematicSim::Config config;
  testing::KinematicSim sim({}, start, config);
  PathTracker tracker(params, config.a_m);
  tracker.SetPath(path);
  double worst = 0.0;
  for (int k = 0; k < 1000 && !tracker.done(); ++k) {
    const Twist2 u = tracker.Command(sim.X_WR(), 0.1);
    EXPECT_LE(std::abs(u.v_mps), params.max_linear_speed_mps + 1e-12);
    EXPECT_LE(std::abs(u.w_radps), params.max_angular_speed_radps + 1e-12);
    sim.Step(u, 0.1);
    if (sim.distance_m() > settle_m) worst = std::max(worst, DistanceToPath(path, sim.X_WR().translation()));
  }
  *done = tracker.done();
  return worst;
}

TEST(PathTrackerTest, ConvergesOnAReferencePathAndReachesItsEnd) {
  const ExplorerParams params;
  const Path path = SmoothPolyline({{0, 0}, {4, 0}, {4, 4}, {1, 5}}, nullptr, params);
  bool done = false;
  // Starting 0.3 m off the path and 0.4 rad off its heading.
  const double worst = Follow(path, Pose2(0.0, -0.3, 0.4), 1.0, &done, params);
  EXPECT_TRUE(done);
  EXPECT_LT(worst, 0.08);
}

TEST(PathTrackerTest, TurnsInPlaceAtAStopPoint) {
  const ExplorerParams params;
  const Path path = SmoothPolyline({{0, 0}, {2, 0}, {0, 0.1}}, nullptr, params);
  bool done = false;
  const double worst = Follow(path, Pose2(0.0, 0.0, 0.0), 0.0, &done, params);
  EXPECT_TRUE(done);
  // Turning in place swings h on a circle of radius a = 0.2 m about the
  // axle: h leaves the path by up to a while it turns, and no more.
  EXPECT_LT(worst, 0.2 + 0.03);
}

TEST(PathTrackerTest, TurnsFirstWhenThePathStartsBehind) {
  const ExplorerParams params;
  const Path path = SmoothPolyline({{0, 0}, {-3, 0}}, nullptr, params);
  testing::KinematicSim sim({}, Pose2(0.0, 0.0, 0.0), {});
  PathTracker tracker(params, 0.2);
  tracker.SetPath(path);
  const Twist2 u = tracker.Command(sim.X_WR(), 0.1);
  EXPECT_EQ(u.v_mps, 0.0);  // never backward, never forward away from it
  EXPECT_NE(u.w_radps, 0.0);
}

TEST(SafetyFilterTest, StopsBeforeAWallAhead) {
  const ExplorerParams params;
  // A wall across the way, 0.06 m ahead of h (the body's front edge is
  // 0.02 m behind h, plus 0.05 m margin: 0.03 m to spare).
  std::vector<Eigen::Vector2d> wall;
  for (double y = -1.0; y <= 1.0; y += 0.02) wall.emplace_back(0.06, y);
  bool limited = false;
  const Twist2 u = SafetyFilter({0.4, 0.0}, Pose2(), wall, params, 0.2, 0.1, &limited);
  EXPECT_TRUE(limited);
  EXPECT_EQ(u.v_mps, 0.0);
  // Farther away (0.15 m): half the speed still stops in time.
  std::vector<Eigen::Vector2d> farther;
  for (double y = -1.0; y <= 1.0; y += 0.02) farther.emplace_back(0.15, y);
  const Twist2 slower = SafetyFilter({0.4, 0.0}, Pose2(), farther, params, 0.2, 0.1, &limited);
  EXPECT_TRUE(limited);
  EXPECT_EQ(slower.v_mps, 0.2);
  // Turning in place is safe with the wall 0.1 m ahead of h (the grown
  // body's front corners swing about 3 cm forward while the turn is held for
  // the period plus the wheels' lag; at 0.06 m they would touch).
  std::vector<Eigen::Vector2d> ahead;
  for (double y = -1.0; y <= 1.0; y += 0.02) ahead.emplace_back(0.10, y);
  const Twist2 turn = SafetyFilter({0.0, 1.0}, Pose2(), ahead, params, 0.2, 0.1, &limited);
  EXPECT_FALSE(limited);
  EXPECT_EQ(turn.w_radps, 1.0);
}

TEST(SafetyFilterTest, LeavesAFreeWayAlone) {
  const ExplorerParams params;
  std::vector<Eigen::Vector2d> far_wall;
  for (double y = -1.0; y <= 1.0; y += 0.02) far_wall.emplace_back(1.5, y);
  bool limited = true;
  const Twist2 u = SafetyFilter({0.4, 0.1}, Pose2(), far_wall, params, 0.2, 0.1, &limited);
  EXPECT_FALSE(limited);
  EXPECT_EQ(u.v_mps, 0.4);
  EXPECT_EQ(u.w_radps, 0.1);
}

TEST(SafetyFilterTest, LongCommandPeriodStopsEarlier) {
  const ExplorerParams params;
  std::vector<Eigen::Vector2d> wall;
  for (double y = -1.0; y <= 1.0; y += 0.02) wall.emplace_back(0.3, y);
  bool limited = false;
  // 0.4 m/s held 0.1 s: 4 cm plus 10 cm braking, fine; held 0.7 s (a slow
  // filter's period): 28 cm plus braking, too far.
  SafetyFilter({0.4, 0.0}, Pose2(), wall, params, 0.2, 0.1, &limited);
  EXPECT_FALSE(limited);
  SafetyFilter({0.4, 0.0}, Pose2(), wall, params, 0.2, 0.7, &limited);
  EXPECT_TRUE(limited);
}

TEST(SafetyFilterTest, WheelDiscsArePartOfTheFootprint) {
  ExplorerParams params;
  params.safety_margin_slow_m = params.safety_margin_m;  // the same margin at every speed
  // Beside the right wheel, outside the body rectangle (|y| > 0.19) but
  // inside the wheel's collision disc (0.165 + 0.0975 = 0.2625).
  const std::vector<Eigen::Vector2d> beside{{-0.2025, -0.24}};
  EXPECT_TRUE(BodyTouches(Pose2(), beside, params, 0.0));
  ExplorerParams no_wheels = params;
  no_wheels.wheel_radius_m = 0.0;
  EXPECT_FALSE(BodyTouches(Pose2(), beside, no_wheels, 0.0));

  // A door jamb: a wall 0.25 m to the right of h's line that ends 0.15 m
  // behind the axle (office, seed 5: backing up out of a door, the right
  // wheel's disc caught the jamb; the body rectangle alone keeps clear).
  std::vector<Eigen::Vector2d> jamb;
  for (double x = -1.5; x <= -0.35 + 1e-9; x += 0.01) jamb.emplace_back(x, -0.25);
  bool limited = false;
  SafetyFilter({-0.1, 0.0}, Pose2(), jamb, no_wheels, 0.2025, 0.3, &limited);
  EXPECT_FALSE(limited);
  const Twist2 u = SafetyFilter({-0.1, 0.0}, Pose2(), jamb, params, 0.2025, 0.3, &limited);
  EXPECT_TRUE(limited);
  EXPECT_GT(u.v_mps, -0.1);  // slower or stopped
}

// The margin shrinks with speed: a robot creeping through a 0.8 m door
// 9.75 cm off its middle (a path a few cm off, occupied cells up to half a
// cell into the opening; the wheels reach 0.2625 m, so 0.04 m is left on the
// near side) may go on; at cruise speed, or with the whole margin at every
// speed (the former rule), the safety layer stops it.
TEST(SafetyFilterTest, CreepingThroughAStandardDoorKeepsASmallerMargin) {
  ExplorerParams params;
  EXPECT_EQ(SafetyMarginM({0.0, 0.0}, params), params.safety_margin_slow_m);
  EXPECT_EQ(SafetyMarginM({0.4, 0.0}, params), params.safety_margin_m);
  EXPECT_EQ(SafetyMarginM({0.0, 1.0}, params), params.safety_margin_m);
  EXPECT_LT(SafetyMarginM({0.1, 0.0}, params), SafetyMarginM({0.2, 0.0}, params));
  // Jambs 0.15 m deep at y = 0.3025 and -0.4975, from 6.5 cm ahead of the
  // wheels' axle: the left wheel's disc is 0.052 m from the jamb's corner,
  // and within the whole margin of it after 2 cm more.
  std::vector<Eigen::Vector2d> jambs;
  for (double x = -0.1375; x <= 0.0125 + 1e-9; x += 0.01) {
    jambs.emplace_back(x, 0.3025);
    jambs.emplace_back(x, -0.4975);
  }
  bool limited = false;
  const Twist2 creep = SafetyFilter({0.1, 0.0}, Pose2(), jambs, params, 0.2025, 0.1, &limited);
  EXPECT_FALSE(limited);
  EXPECT_EQ(creep.v_mps, 0.1);
  SafetyFilter({0.4, 0.0}, Pose2(), jambs, params, 0.2025, 0.1, &limited);
  EXPECT_TRUE(limited);
  ExplorerParams fixed = params;
  fixed.safety_margin_slow_m = fixed.safety_margin_m;
  SafetyFilter({0.1, 0.0}, Pose2(), jambs, fixed, 0.2025, 0.1, &limited);
  EXPECT_TRUE(limited);
}

TEST(SafetyFilterTest, BodyClearanceIsTheMarginAtWhichTheBodyTouches) {
  ExplorerParams params;
  const Pose2 X_WR(1.0, -2.0, 0.7);
  // Points around the body (rectangle and wheel discs), from inside to 0.3 m out.
  for (double x = -0.8; x <= 0.3; x += 0.037) {
    for (double y = -0.6; y <= 0.6; y += 0.041) {
      const std::vector<Eigen::Vector2d> point{X_WR * Eigen::Vector2d(x, y)};
      const double clearance = BodyClearanceM(X_WR, point, params);
      EXPECT_TRUE(BodyTouches(X_WR, point, params, clearance + 1e-9)) << x << " " << y;
      if (clearance > 1e-9) {
        EXPECT_FALSE(BodyTouches(X_WR, point, params, clearance - 1e-9)) << x << " " << y;
      }
    }
  }
  EXPECT_EQ(BodyClearanceM(X_WR, {}, params), std::numeric_limits<double>::infinity());
}

// Wedged at a door's jamb (floor_14x8_d080, seed 10, true pose at 88 s): a
// wall 0.15 m thick below y = 2.9 from the jamb at x = 9.0 on, the robot at
// (8.96, 3.246) heading 41 deg, its right wheel's disc 0.025 m from the jamb's
// corner: inside the margin of every moving command (0.03 m and more), outside
// the slow one (0.02 m). Every motion touched the margin at once, so the
// safety layer stopped each recovery and the robot stood there until no goal
// was left. A motion that comes no closer is allowed now; one toward the
// jamb is still refused.
TEST(SafetyFilterTest, ARobotWedgedAtAJambMayMoveAway) {
  ExplorerParams params;
  std::vector<Eigen::Vector2d> jamb;
  for (double x = 9.0; x <= 10.0 + 1e-9; x += 0.01) jamb.emplace_back(x, 2.9);
  for (double y = 2.75; y < 2.9; y += 0.01) jamb.emplace_back(9.0, y);
  const Pose2 X_WR(8.96, 3.246, DegToRad(41.0));
  const double clearance = BodyClearanceM(X_WR, jamb, params);
  EXPECT_GT(clearance, params.safety_margin_slow_m);
  EXPECT_LT(clearance, SafetyMarginM({0.1, 0.0}, params));
  const double a_m = 0.2025;
  bool limited = true;
  // Turning clockwise swings the right wheel up, away from the corner.
  const Twist2 away = SafetyFilter({0.0, -0.4}, X_WR, jamb, params, a_m, 0.1, &limited);
  EXPECT_FALSE(limited);
  EXPECT_EQ(away.w_radps, -0.4);
  // Driving forward brings the right side nearer the corner.
  SafetyFilter({0.1, 0.0}, X_WR, jamb, params, a_m, 0.1, &limited);
  EXPECT_TRUE(limited);
}

TEST(ExplorerParamsTest, DefaultsAreValidAndBadValuesAreNamed) {
  EXPECT_TRUE(ExplorerParams{}.Validate().empty());
  ExplorerParams params;
  params.clearance_m = 0.1;
  params.grid_resolution_m = -1.0;
  try {
    params.ValidateOrThrow();
    FAIL() << "no throw";
  } catch (const ParamError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("explorer.clearance_m"), std::string::npos) << what;
    EXPECT_NE(what.find("0.1"), std::string::npos) << what;
    EXPECT_NE(what.find("explorer.grid_resolution_m"), std::string::npos) << what;
  }
  EXPECT_THROW(Explorer(ExplorerParams{}, 0.0), ParamError);
}

// A clearance above the turning room is a valid config (the turning room is
// then met wherever a path may go): run directories made with the former
// default clearance_m 0.5 load and evaluate. A turning room of 0 does not.
TEST(ExplorerParamsTest, TurningRoomBelowTheClearanceIsValid) {
  ExplorerParams params;
  params.clearance_m = 0.5;
  params.preferred_clearance_m = 0.9;
  EXPECT_TRUE(params.Validate().empty());
  params.turn_clearance_m = 0.0;
  EXPECT_FALSE(params.Validate().empty());
}

}  // namespace
}  // namespace mjslam::explorer
