// The explorer with its default parameters in the geometry of every shipped
// world (worlds/*.xml read as wall segments), in the test-only kinematic
// simulator with an exact 30 m laser and the true pose: it must see at least
// 95 % of the reachable free area, never touch a wall, and end with a reason
// within 10 minutes of simulated time, with a command period of 0.1 s (and
// 0.5 s, a slow filter's period, in one world), and in one world with an
// error in the pose given to the explorer. The SLAM and MuJoCo are not involved.

#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>

#include <gtest/gtest.h>

#include "explorer/explorer.h"
#include "tests/support/kinematic_sim.h"
#include "tests/support/seen_area.h"
#include "tests/support/world_walls.h"

namespace mjslam::explorer {
namespace {

struct Case {
  const char* world;
  double dt_s;
  /// Give the explorer a pose estimate off the truth by a slowly varying
  /// error (up to 5 cm in x and y and 1.1 deg), as a SLAM estimate would be.
  bool pose_error = false;
};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.world << " dt " << c.dt_s << (c.pose_error ? " with pose error" : "");
}

class ExplorerWorldsTest : public ::testing::TestWithParam<Case> {};

TEST_P(ExplorerWorldsTest, ExploresTheWorldWithoutContact) {
  const Case c = GetParam();
  const std::string path = std::string(MJSLAM_SOURCE_DIR) + "/worlds/" + c.world;
  const testing::WorldWalls world = testing::ReadWorldWalls(path);
  ASSERT_TRUE(world.has_start) << path;
  testing::KinematicSim::Config config;
  config.max_range_m = 30.0;
  testing::KinematicSim sim(world.walls, world.X_WR_start, config);
  testing::SeenArea seen(world.walls, world.X_WR_start.translation());
  Explorer explorer(ExplorerParams{}, config.a_m);
  ExplorerOutput out;
  double t = 0.0;
  for (; t < 600.0 && !out.finished; t += c.dt_s) {
    const LaserScan scan = sim.Scan(t);
    seen.Add(scan, sim.X_WR() * config.X_RS);
    const Pose2 error = c.pose_error ? Pose2(0.05 * std::sin(t / 10.0), 0.05 * std::cos(t / 7.0),
                                             0.02 * std::sin(t / 5.0))
                                     : Pose2();
    out = explorer.Step(sim.X_WR() * error, &scan, config.X_RS, t, c.dt_s);
    sim.Step(out.command, c.dt_s);
  }
  std::printf("%s dt %.1f s: %s at t = %.1f s, explored %.3f of %.1f m^2, %.1f m, contacts %d\n",
              c.world, c.dt_s, out.finish_reason.c_str(), t, seen.Fraction(),
              seen.ReachableArea(), sim.distance_m(), sim.contacts());
  EXPECT_TRUE(out.finished);
  EXPECT_FALSE(out.finish_reason.empty());
  EXPECT_GE(seen.Fraction(), 0.95);
  EXPECT_EQ(sim.contacts(), 0);
}

INSTANTIATE_TEST_SUITE_P(
    ShippedWorlds, ExplorerWorldsTest,
    ::testing::Values(Case{"room.xml", 0.1}, Case{"corridor_loop.xml", 0.1},
                      Case{"office.xml", 0.1}, Case{"pillars.xml", 0.1},
                      Case{"corridor_loop.xml", 0.5}, Case{"pillars.xml", 0.1, true}),
    [](const ::testing::TestParamInfo<Case>& info) {
      std::string name = info.param.world;
      name = name.substr(0, name.find('.'));
      return name + (info.param.dt_s > 0.2 ? "_slow" : "") +
             (info.param.pose_error ? "_pose_error" : "");
    });

}  // namespace
}  // namespace mjslam::explorer
