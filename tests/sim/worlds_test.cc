// Every shipped world (worlds/*.xml, found at run time, so new worlds are
// covered): it loads with the robot, its start pose is collision-free, its
// obstacles stand on the floor and reach above the laser, its tour keeps
// clear of the walls, and the robot can drive the whole tour with a simple
// point-h controller without touching anything (tours up to 200 m here; the
// long tours of the generated buildings in building_tours_test.cc, label
// `slow`).

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "sim/obstacles.h"
#include "sim/scene.h"
#include "sim/simulator.h"
#include "tests/sim/sim_test_util.h"
#include "tests/sim/tour_drive.h"

namespace mjslam::sim {
namespace {

using testing::MujocoTest;
using testing::DriveTour;
using testing::RobotModelPath;
using testing::TourLength;

std::vector<std::string> ShippedWorlds() {
  std::vector<std::string> worlds;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(MJSLAM_SOURCE_DIR) + "/worlds")) {
    if (entry.path().extension() == ".xml") worlds.push_back(entry.path().string());
  }
  std::sort(worlds.begin(), worlds.end());
  return worlds;
}

// Tours longer than this are driven by building_tours_test (label slow), metres.
constexpr double kLongTourM = 200.0;

std::string BaseName(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

class WorldsTest : public MujocoTest {};

TEST_F(WorldsTest, TheRequiredWorldsAreShipped) {
  std::vector<std::string> names;
  for (const std::string& world : ShippedWorlds()) names.push_back(BaseName(world));
  for (const char* required : {"room.xml", "corridor_loop.xml", "office.xml", "pillars.xml"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
  }
}

TEST_F(WorldsTest, EveryWorldLoadsWithAFreeStartAndAClearTour) {
  for (const std::string& world : ShippedWorlds()) {
    SCOPED_TRACE(world);
    const Scene scene(world, RobotModelPath());
    Simulator sim(scene, SimParams{}, RobotParams{});
    EXPECT_EQ(sim.CountRobotWorldContacts(), 0);
    const Pose2 start = scene.StartPose();
    EXPECT_NEAR(sim.X_WR().x, start.x, 1e-3);
    EXPECT_NEAR(sim.X_WR().y, start.y, 1e-3);

    // Obstacles: exact shapes, on the floor, taller than the laser.
    const std::vector<ObstacleFootprint>& obstacles = scene.Obstacles();
    ASSERT_FALSE(obstacles.empty());
    for (const ObstacleFootprint& obstacle : obstacles) {
      EXPECT_TRUE(obstacle.exact) << obstacle.name;
      EXPECT_LE(obstacle.z_min_m, 0.01) << obstacle.name;
      EXPECT_GE(obstacle.z_max_m, 0.9) << obstacle.name;
    }

    // Tour: at least 3 waypoints, each >= 0.5 m from every obstacle, and so
    // is every point of the closed polyline between them, except the legs
    // through doors narrower than 1.2 m, which keep >= 0.35 m (a 0.8 m door
    // passed through its middle leaves 0.4 m; worlds/README.md).
    const std::vector<Eigen::Vector2d>& tour = scene.TourWaypoints();
    ASSERT_GE(tour.size(), 3u);
    double closest = 1e9;
    int door_legs = 0;
    for (std::size_t i = 0; i < tour.size(); ++i) {
      EXPECT_GE(DistanceToObstacles(tour[i], obstacles), 0.5) << "tour_" << i;
      const Eigen::Vector2d& a = tour[i];
      const Eigen::Vector2d& b = tour[(i + 1) % tour.size()];
      double leg_closest = 1e9;
      for (int k = 0; k <= 100; ++k) {
        const Eigen::Vector2d p = a + (b - a) * (k / 100.0);
        leg_closest = std::min(leg_closest, DistanceToObstacles(p, obstacles));
      }
      EXPECT_GE(leg_closest, 0.35) << "tour_" << i << " -> next";
      door_legs += leg_closest < 0.5;
      closest = std::min(closest, leg_closest);
    }
    std::cout << BaseName(world) << ": " << obstacles.size() << " obstacles, " << tour.size()
              << " waypoints, closest approach of the tour " << closest << " m, " << door_legs
              << " legs through doors\n";

    // The laser sees walls from the start, and never closer than the
    // geometry allows (the laser is behind h, inside the free space).
    const LaserScan scan = sim.CastLaser(LaserParams{});
    int returns = 0;
    for (int i = 0; i < scan.size(); ++i) returns += scan.has_return[i];
    EXPECT_GT(returns, 0);
  }
}

TEST_F(WorldsTest, TheRobotDrivesEveryTourWithoutTouchingAnything) {
  for (const std::string& world : ShippedWorlds()) {
    SCOPED_TRACE(world);
    Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{});
    if (TourLength(sim.scene().TourWaypoints()) > kLongTourM) {
      std::cout << BaseName(world) << ": tour longer than " << kLongTourM
                << " m, driven in building_tours_test\n";
      continue;
    }
    const double driven = DriveTour(&sim, 0.5);
    std::cout << BaseName(world) << ": drove the tour, " << driven << " m in " << sim.time_s()
              << " s\n";
    EXPECT_GT(driven, 5.0);
  }
}

}  // namespace
}  // namespace mjslam::sim
