// The long tours of the generated buildings (worlds/building_*.xml): the
// robot drives each whole tour, through every door (0.85 m), with the
// point-h controller of worlds_test.cc, without touching anything. Label
// `slow` (about a minute each on the development machine).
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "sim/simulator.h"
#include "tests/sim/sim_test_util.h"
#include "tests/sim/tour_drive.h"

namespace mjslam::sim {
namespace {

class BuildingToursTest : public testing::MujocoTest,
                          public ::testing::WithParamInterface<std::string> {};

TEST_P(BuildingToursTest, TheRobotDrivesTheWholeTourWithoutTouchingAnything) {
  Simulator sim(testing::WorldPath(GetParam()), testing::RobotModelPath(), SimParams{},
                RobotParams{});
  const double length = testing::TourLength(sim.scene().TourWaypoints());
  const double driven = testing::DriveTour(&sim, 0.5);
  std::cout << GetParam() << ": drove the tour (" << length << " m between waypoints), "
            << driven << " m in " << sim.time_s() << " s\n";
  EXPECT_GT(driven, 0.8 * length);
}

INSTANTIATE_TEST_SUITE_P(Buildings, BuildingToursTest,
                         ::testing::Values("building_40x30.xml", "building_80x50.xml"));

}  // namespace
}  // namespace mjslam::sim
