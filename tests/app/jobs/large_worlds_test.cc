// The generated buildings (worlds/building_*.xml) load, and their ground
// truth and coverage grid have the size a floor of that many rooms should:
// the order of the feature count, the reachable area a large share of the
// floor. Also prints how long the setup takes (not asserted).
#include <chrono>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "app/jobs/evaluate.h"
#include "app/engine/true_coverage.h"
#include "sim/scene.h"

namespace mjslam::app {
namespace {

struct Building {
  std::string file;
  double floor_m2;      // inside area of the outer walls
  int min_features;     // order of the reachable true features
  int max_features;
};

// Test names and messages show the world's file.
void PrintTo(const Building& b, std::ostream* os) { *os << b.file; }

class LargeWorldsTest : public ::testing::TestWithParam<Building> {};

TEST_P(LargeWorldsTest, GroundTruthAndCoverageHaveTheExpectedSize) {
  const Building& b = GetParam();
  const std::string world = std::string(MJSLAM_SOURCE_DIR) + "/worlds/" + b.file;
  const std::string robot = std::string(MJSLAM_SOURCE_DIR) + "/models/pioneer3dx.xml";
  const auto t0 = std::chrono::steady_clock::now();
  const eval::Map truth = WorldGroundTruth(world, robot);
  const auto t1 = std::chrono::steady_clock::now();
  int lines = 0;
  int corners = 0;
  for (const MapFeature& f : truth) {
    (f.type == MapFeature::Type::kLine ? lines : corners) += 1;
  }
  EXPECT_GE(static_cast<int>(truth.size()), b.min_features);
  EXPECT_LE(static_cast<int>(truth.size()), b.max_features);
  // Every corner joins two lines: about as many corners as lines.
  EXPECT_GT(corners, lines / 2);
  EXPECT_LT(corners, 2 * lines);

  const sim::Scene scene(world, robot);
  const auto t2 = std::chrono::steady_clock::now();
  const TrueCoverage coverage(scene.Obstacles(), scene.StartPose().translation());
  const auto t3 = std::chrono::steady_clock::now();
  // Corridors, rooms and halls: most of the floor, less walls and closed voids.
  EXPECT_GT(coverage.ReachableArea(), 0.7 * b.floor_m2);
  EXPECT_LT(coverage.ReachableArea(), b.floor_m2);
  std::cout << b.file << ": " << scene.Obstacles().size() << " geoms, " << truth.size()
            << " true features (" << lines << " lines, " << corners << " corners) in "
            << std::chrono::duration<double>(t1 - t0).count() << " s, reachable area "
            << coverage.ReachableArea() << " m^2 in "
            << std::chrono::duration<double>(t3 - t2).count() << " s\n";
}

INSTANTIATE_TEST_SUITE_P(Buildings, LargeWorldsTest,
                         ::testing::Values(Building{"building_40x30.xml", 1200.0, 400, 1500},
                                           Building{"building_80x50.xml", 4000.0, 1500, 6000}),
                         [](const ::testing::TestParamInfo<Building>& info) {
                           return info.param.file.substr(0, info.param.file.find('.'));
                         });

}  // namespace
}  // namespace mjslam::app
