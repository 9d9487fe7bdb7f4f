// The exact laser cast against analytic ray-segment geometry, in inline MJCF
// worlds (walls at any yaw, pillars): ranges agree to 1 mm, beams without an
// echo report max range and no-return, the robot never sees itself, and
// angular offsets move the beams.

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "sim/simulator.h"
#include "tests/sim/sim_test_util.h"

namespace mjslam::sim {
namespace {

using testing::MujocoTest;
using testing::RobotModelPath;
using testing::WorldXml;
using testing::WriteTempFile;

// An upright box wall or a cylinder pillar, 1 m tall, standing on the floor.
struct TestObstacle {
  bool is_box = true;
  double x = 0.0;
  double y = 0.0;
  double yaw_deg = 0.0;
  double half_x = 0.0;  // box half extents, or cylinder radius in half_x
  double half_y = 0.0;
};

std::string ObstaclesXml(const std::vector<TestObstacle>& obstacles) {
  std::ostringstream xml;
  xml.precision(17);
  for (const TestObstacle& o : obstacles) {
    if (o.is_box) {
      xml << "<geom type=\"box\" size=\"" << o.half_x << " " << o.half_y << " 0.5\" pos=\""
          << o.x << " " << o.y << " 0.5\" euler=\"0 0 " << o.yaw_deg << "\"/>\n";
    } else {
      xml << "<geom type=\"cylinder\" size=\"" << o.half_x << " 0.5\" pos=\"" << o.x << " "
          << o.y << " 0.5\"/>\n";
    }
  }
  return xml.str();
}

// Distance along the ray p + t u (t >= 0, |u| = 1) to the first hit on the
// obstacle's outline, if any. Independent of MuJoCo: slab test for boxes,
// quadratic for circles.
std::optional<double> RayHit(const Eigen::Vector2d& p, const Eigen::Vector2d& u,
                             const TestObstacle& o) {
  const Eigen::Vector2d c(o.x, o.y);
  if (!o.is_box) {
    const Eigen::Vector2d m = p - c;
    const double b = m.dot(u);
    const double disc = b * b - (m.squaredNorm() - o.half_x * o.half_x);
    if (disc < 0.0) return std::nullopt;
    const double t = -b - std::sqrt(disc);
    if (t < 0.0) return std::nullopt;
    return t;
  }
  // Ray in the box frame.
  const double yaw = DegToRad(o.yaw_deg);
  const double cs = std::cos(yaw);
  const double sn = std::sin(yaw);
  const Eigen::Vector2d d = p - c;
  const Eigen::Vector2d p_B(cs * d.x() + sn * d.y(), -sn * d.x() + cs * d.y());
  const Eigen::Vector2d u_B(cs * u.x() + sn * u.y(), -sn * u.x() + cs * u.y());
  const double half[2] = {o.half_x, o.half_y};
  double t_enter = -std::numeric_limits<double>::infinity();
  double t_exit = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 2; ++k) {
    if (std::abs(u_B[k]) < 1e-15) {
      if (std::abs(p_B[k]) > half[k]) return std::nullopt;
      continue;
    }
    double t0 = (-half[k] - p_B[k]) / u_B[k];
    double t1 = (half[k] - p_B[k]) / u_B[k];
    if (t0 > t1) std::swap(t0, t1);
    t_enter = std::max(t_enter, t0);
    t_exit = std::min(t_exit, t1);
  }
  if (t_enter > t_exit || t_enter < 0.0) return std::nullopt;
  return t_enter;
}

// The analytic scan from laser pose X_WS.
std::vector<std::optional<double>> AnalyticRanges(const Pose2& X_WS, const LaserParams& laser,
                                                  const std::vector<TestObstacle>& obstacles) {
  std::vector<std::optional<double>> ranges;
  for (int i = 0; i < laser.num_beams; ++i) {
    const double bearing = X_WS.theta + laser.AngleMinRad() + i * laser.AngleIncrementRad();
    const Eigen::Vector2d u(std::cos(bearing), std::sin(bearing));
    std::optional<double> best;
    for (const TestObstacle& o : obstacles) {
      const std::optional<double> hit = RayHit(X_WS.translation(), u, o);
      if (hit && *hit < laser.max_range_m && (!best || *hit < *best)) best = hit;
    }
    ranges.push_back(best);
  }
  return ranges;
}

class SimulatorLaserTest : public MujocoTest {
 protected:
  // Checks every beam of an exact scan from X_WR against the analytic ranges.
  void ExpectScanMatchesGeometry(const std::string& name,
                                 const std::vector<TestObstacle>& obstacles,
                                 const Pose2& X_WR, const LaserParams& laser = {}) {
    const std::string world = WriteTempFile(name, WorldXml(ObstaclesXml(obstacles)));
    Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{}, X_WR);
    const LaserScan scan = sim.CastLaser(laser);
    ASSERT_EQ(scan.size(), laser.num_beams);
    EXPECT_DOUBLE_EQ(scan.angle_min_rad, -kPi / 2);
    EXPECT_DOUBLE_EQ(scan.angle_increment_rad, DegToRad(1.0));
    EXPECT_EQ(scan.max_range_m, laser.max_range_m);
    const std::vector<std::optional<double>> expected =
        AnalyticRanges(sim.X_WS(), laser, obstacles);
    int returns = 0;
    double max_error = 0.0;
    for (int i = 0; i < scan.size(); ++i) {
      if (expected[i]) {
        ++returns;
        max_error = std::max(max_error, std::abs(scan.ranges_m[i] - *expected[i]));
        EXPECT_EQ(scan.has_return[i], 1) << name << " beam " << i;
        EXPECT_NEAR(scan.ranges_m[i], *expected[i], 1e-3) << name << " beam " << i;
      } else {
        EXPECT_EQ(scan.has_return[i], 0) << name << " beam " << i;
        EXPECT_EQ(scan.ranges_m[i], laser.max_range_m) << name << " beam " << i;
      }
    }
    EXPECT_GT(returns, 0) << name;
    std::cout << name << ": " << returns << " echoes, largest error " << max_error << " m\n";
  }
};

TEST_F(SimulatorLaserTest, HandCheckedBeamsInARawStringWorld) {
  // A wall facing the robot (inner face x = 2.9) and a wall at 45 degrees to
  // its left whose face passes through (0, 2) and (2, 4) before the yaw.
  const std::string world = WriteTempFile("raw_world.xml", R"(
<mujoco model="raw">
  <worldbody>
    <geom name="floor" type="plane" size="20 20 0.1"/>
    <geom name="front" type="box" size="0.1 3 0.5" pos="3 0 0.5"/>
    <geom name="diagonal" type="box" size="2 0.1 0.5" pos="0 3 0.5" euler="0 0 45"/>
    <site name="start" pos="0 0 0"/>
  </worldbody>
</mujoco>
)");
  Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{});
  const LaserScan scan = sim.CastLaser(LaserParams{});
  const double x_S = sim.X_WS().x;  // -0.179: the laser is behind h
  EXPECT_NEAR(x_S, -0.179, 1e-3);  // after settling on the soft contacts
  // Beam 90 (straight ahead) hits the front wall's face at x = 2.9.
  EXPECT_NEAR(scan.ranges_m[90], 2.9 - x_S, 1e-9);
  // Beam 180 (90 deg left, along +y from (x_S, 0)) hits the diagonal wall's
  // lower face: the line y = x + 3 - 0.1 sqrt(2) (its centre line y = x + 3,
  // shifted down by the half thickness along the normal).
  EXPECT_NEAR(scan.ranges_m[180], x_S + 3.0 - 0.1 * std::sqrt(2.0), 1e-9);
  // Beam 0 (90 deg right) sees nothing.
  EXPECT_EQ(scan.has_return[0], 0);
  EXPECT_EQ(scan.ranges_m[0], 30.0);
}

TEST_F(SimulatorLaserTest, RangesToAnAxisAlignedWallMatchGeometry) {
  ExpectScanMatchesGeometry("wall_ahead.xml", {{true, 3.0, 0.0, 0.0, 0.1, 2.0}}, Pose2(0, 0, 0));
}

TEST_F(SimulatorLaserTest, RangesToRotatedWallsAndPillarsMatchGeometry) {
  const std::vector<TestObstacle> obstacles = {
      {true, 4.0, 1.0, 30.0, 0.075, 2.5},    // rotated wall ahead-left
      {true, 1.5, -3.0, -65.0, 0.1, 1.5},    // rotated wall right
      {true, -0.5, 4.0, 100.0, 0.05, 3.0},   // wall to the left, almost axis-aligned
      {true, 2.5, 3.0, 45.0, 0.4, 0.4},      // a square column rotated 45 degrees
      {false, 2.0, -0.8, 0.0, 0.25, 0.0},    // pillar
      {false, 6.0, -2.0, 0.0, 0.15, 0.0},    // pillar
  };
  ExpectScanMatchesGeometry("rotated_walls_a.xml", obstacles, Pose2(0, 0, 0));
  ExpectScanMatchesGeometry("rotated_walls_b.xml", obstacles, Pose2(0.3, -0.2, DegToRad(37.0)));
  ExpectScanMatchesGeometry("rotated_walls_c.xml", obstacles, Pose2(-0.5, 0.5, DegToRad(-120.0)));
}

TEST_F(SimulatorLaserTest, ClosedRoomGivesAnEchoOnEveryBeam) {
  // A 6 x 4 m room of 0.1 m walls; the robot inside sees a wall on every beam.
  const std::vector<TestObstacle> room = {
      {true, 3.05, 0.0, 0.0, 0.05, 2.1},
      {true, -3.05, 0.0, 0.0, 0.05, 2.1},
      {true, 0.0, 2.05, 0.0, 3.1, 0.05},
      {true, 0.0, -2.05, 0.0, 3.1, 0.05},
  };
  ExpectScanMatchesGeometry("room.xml", room, Pose2(-1.0, 0.4, DegToRad(12.0)));
  const std::string world = WriteTempFile("room_returns.xml", WorldXml(ObstaclesXml(room)));
  Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{}, Pose2(0, 0, 1.0));
  const LaserScan scan = sim.CastLaser(LaserParams{});
  for (int i = 0; i < scan.size(); ++i) EXPECT_EQ(scan.has_return[i], 1) << "beam " << i;
}

TEST_F(SimulatorLaserTest, RobotNeverSeesItselfAndFloorGivesNoEcho) {
  // Only the floor: every beam is a no-return at max range, whatever the yaw.
  const std::string world = WriteTempFile("floor_only.xml", WorldXml(""));
  for (const double yaw : {0.0, 1.0, -2.5}) {
    Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{}, Pose2(0, 0, yaw));
    const LaserScan scan = sim.CastLaser(LaserParams{});
    for (int i = 0; i < scan.size(); ++i) {
      EXPECT_EQ(scan.has_return[i], 0) << "yaw " << yaw << " beam " << i;
      EXPECT_EQ(scan.ranges_m[i], 30.0);
    }
  }
}

TEST_F(SimulatorLaserTest, BeyondMaxRangeIsNoReturn) {
  const std::string world = WriteTempFile(
      "far_wall.xml", WorldXml(ObstaclesXml({{true, 40.0, 0.0, 0.0, 0.1, 5.0}})));
  Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{}, Pose2(0, 0, 0));
  LaserParams laser;
  const LaserScan short_scan = sim.CastLaser(laser);
  EXPECT_EQ(short_scan.has_return[90], 0);
  EXPECT_EQ(short_scan.ranges_m[90], 30.0);
  laser.max_range_m = 50.0;
  const LaserScan long_scan = sim.CastLaser(laser);
  EXPECT_EQ(long_scan.has_return[90], 1);
  EXPECT_NEAR(long_scan.ranges_m[90], 39.9 - sim.X_WS().x, 1e-9);
}

TEST_F(SimulatorLaserTest, LaserFrameIsTheModelSiteRelativeToPointH) {
  const RobotParams robot;
  const std::string world = WriteTempFile("frames.xml", WorldXml(""));
  const Pose2 X_WR_start(1.0, 2.0, 0.7);
  Simulator sim(world, RobotModelPath(), SimParams{}, robot, X_WR_start);
  // The SICK is 21 mm ahead of the axle, the point h is a ahead of it.
  EXPECT_NEAR(sim.X_RS().x, 0.021 - robot.control_point_offset_m, 1e-9);
  EXPECT_NEAR(sim.X_RS().y, 0.0, 1e-9);
  EXPECT_NEAR(sim.X_RS().theta, 0.0, 1e-9);
  const Pose2 composed = sim.X_WR() * sim.X_RS();
  EXPECT_NEAR(sim.X_WS().x, composed.x, 1e-12);
  EXPECT_NEAR(sim.X_WS().y, composed.y, 1e-12);
}

TEST_F(SimulatorLaserTest, AngleOffsetsMoveTheBeamsButNotTheReportedBearings) {
  const std::vector<TestObstacle> obstacles = {{true, 3.0, 0.5, 20.0, 0.1, 3.0},
                                               {false, 1.0, 1.5, 0.0, 0.3, 0.0}};
  const std::string world = WriteTempFile("offsets.xml", WorldXml(ObstaclesXml(obstacles)));
  Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{}, Pose2(0, 0, 0));
  const LaserParams laser;
  const LaserScan nominal = sim.CastLaser(laser);
  // Offsetting every beam by one increment casts beam i where beam i+1 was.
  const std::vector<double> offsets(laser.num_beams, laser.AngleIncrementRad());
  const LaserScan shifted = sim.CastLaser(laser, offsets);
  EXPECT_EQ(shifted.angle_min_rad, nominal.angle_min_rad);
  for (int i = 0; i + 1 < laser.num_beams; ++i) {
    EXPECT_NEAR(shifted.ranges_m[i], nominal.ranges_m[i + 1], 1e-9) << "beam " << i;
    EXPECT_EQ(shifted.has_return[i], nominal.has_return[i + 1]) << "beam " << i;
  }
  EXPECT_THROW(sim.CastLaser(laser, std::vector<double>(3, 0.0)), SimError);
}

TEST_F(SimulatorLaserTest, CustomBeamLayout) {
  const std::vector<TestObstacle> obstacles = {{true, 2.0, 0.0, -10.0, 0.1, 4.0},
                                               {true, 0.0, 2.0, 80.0, 0.1, 4.0}};
  LaserParams laser;
  laser.num_beams = 361;
  laser.fov_deg = 270.0;
  laser.max_range_m = 8.0;
  const std::string world = WriteTempFile("custom_layout.xml", WorldXml(ObstaclesXml(obstacles)));
  Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{}, Pose2(0, 0, 0.2));
  const LaserScan scan = sim.CastLaser(laser);
  ASSERT_EQ(scan.size(), 361);
  EXPECT_NEAR(scan.angle_min_rad, DegToRad(-135.0), 1e-12);
  EXPECT_NEAR(scan.angle_increment_rad, DegToRad(0.75), 1e-12);
  const std::vector<std::optional<double>> expected = AnalyticRanges(sim.X_WS(), laser, obstacles);
  for (int i = 0; i < scan.size(); ++i) {
    EXPECT_EQ(scan.has_return[i], expected[i] ? 1 : 0) << "beam " << i;
    if (expected[i]) {
      EXPECT_NEAR(scan.ranges_m[i], *expected[i], 1e-3) << "beam " << i;
    }
  }
}

}  // namespace
}  // namespace mjslam::sim
