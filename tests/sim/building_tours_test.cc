// The long tours of the generated buildings (worlds/building_*.xml): the
// robot drives the whole tour of the 40 x 30 m building (31 rooms) and the
// first 500 m of the 80 x 50 m one's (about 30 rooms; its doors are made the
// same way), through every door (0.85 m), with the point-h controller of
// worlds_test.cc, without touching anything. Label `slow` (about a minute
// each on an idle 2-core machine). The whole tours with the app's tour
// driver: docs/results.md, "Large buildings".
#include <algorithm>
#include <iostream>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "sim/simulator.h"
#include "tests/sim/sim_test_util.h"
#include "tests/sim/tour_drive.h"

namespace mjslam::sim {
namespace {

constexpr double kWhole = std::numeric_limits<double>::infinity();

struct Tour {
  std::string world;
  double max_driven_m;  // infinity: the whole tour
};

// Test names and messages show the world's file.
void PrintTo(const Tour& t, std::ostream* os) { *os << t.world; }

class BuildingToursTest : public testing::MujocoTest,
                          public ::testing::WithParamInterface<Tour> {};

TEST_P(BuildingToursTest, TheRobotDrivesTheWholeTourWithoutTouchingAnything) {
  const Tour& tour = GetParam();
  Simulator sim(testing::WorldPath(tour.world), testing::RobotModelPath(), SimParams{},
                RobotParams{});
  const double length = testing::TourLength(sim.scene().TourWaypoints());
  const double driven = testing::DriveTour(&sim, 0.5, tour.max_driven_m);
  std::cout << tour.world << ": drove " << driven << " m of the tour (" << length
            << " m between waypoints) in " << sim.time_s() << " s\n";
  EXPECT_GT(driven, 0.8 * std::min(length, tour.max_driven_m));
}

INSTANTIATE_TEST_SUITE_P(Buildings, BuildingToursTest,
                         ::testing::Values(Tour{"building_40x30.xml", kWhole},
                                           Tour{"building_80x50.xml", 500.0}),
                         [](const ::testing::TestParamInfo<Tour>& info) {
                           return info.param.world.substr(0, info.param.world.find('.'));
                         });

}  // namespace
}  // namespace mjslam::sim
