// CheckLineObservations (what `mjslam evaluate` writes as summary.json's
// `observations`) on hand-made scans.csv files whose walls are known: the NIS
// of straight walls seen with the modelled noise is chi-square with 2 dof, and
// two parallel walls 5 cm apart give one line far off its covariance unless
// the extractor's fit test splits them.
#include "app/jobs/observation_check.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/map_feature.h"

namespace mjslam::app {
namespace {

namespace fs = std::filesystem;

// A line x = x_wall of the true map, seen from y_min to y_max.
MapFeature Wall(double x_wall, double y_min, double y_max) {
  MapFeature wall;
  wall.type = FeatureType::kLine;
  wall.params = Eigen::Vector2d(x_wall, 0.0);
  wall.has_segment = true;
  wall.p_WA = Eigen::Vector2d(x_wall, y_min);
  wall.p_WB = Eigen::Vector2d(x_wall, y_max);
  return wall;
}

// Writes `scans` scans of the default laser from the origin, looking along
// +x, into DIR/scans.csv: the wall x = 2 up to 45 deg, then the wall x =
// 2 + step_m up to 60 deg (no return beyond), ranges with N(0, 5 mm) noise.
std::string WriteScans(const std::string& name, int scans, double step_m) {
  const fs::path dir =
      fs::temp_directory_path() / ("mjslam_observation_check_" + name + "_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const RunConfig config;
  std::mt19937 engine(11);
  std::normal_distribution<double> noise(0.0, 0.005);
  std::ofstream out(dir / "scans.csv");
  out << "t,x,y,th";
  for (int b = 0; b < config.laser.num_beams; ++b) out << ",r" << b;
  out << "\n";
  for (int s = 0; s < scans; ++s) {
    out << 0.1 * s << ",0,0,0";
    for (int b = 0; b < config.laser.num_beams; ++b) {
      const double phi = config.laser.AngleMinRad() + b * config.laser.AngleIncrementRad();
      double range = config.laser.max_range_m;
      if (std::abs(phi) <= DegToRad(45.0) + 1e-9) {
        range = 2.0 / std::cos(phi) + noise(engine);
      } else if (phi > 0.0 && phi <= DegToRad(60.0) + 1e-9) {
        range = (2.0 + step_m) / std::cos(phi) + noise(engine);
      }
      out << "," << range;
    }
    out << "\n";
  }
  return (dir / "scans.csv").string();
}

TEST(ObservationCheckTest, StraightWallsWithTheModelledNoiseHaveChiSquareNis) {
  const std::string path = WriteScans("straight", 300, 0.0);
  const eval::Map truth = {Wall(2.0, -2.0, 3.5)};
  const ObservationCheck check = CheckLineObservations(path, RunConfig{}, truth);
  EXPECT_EQ(check.lines, 300);
  EXPECT_EQ(check.matched, 300);
  // 300 draws of chi-square(2): mean 2, standard error 0.12.
  EXPECT_GT(check.mean_nis, 1.6);
  EXPECT_LT(check.mean_nis, 2.4);
  EXPECT_LT(check.fraction_above_gate, 0.04);
  EXPECT_NEAR(check.range_bias_m, 0.0, 0.002);
  fs::remove_all(fs::path(path).parent_path());
}

TEST(ObservationCheckTest, MarksSeenTheTrueFeaturesTheScansShow) {
  const std::string path = WriteScans("seen", 20, 0.0);
  // The wall the laser sees; one behind it; a corner out of its view.
  MapFeature corner;
  corner.type = FeatureType::kCorner;
  corner.params = Eigen::Vector2d(-3.0, 2.0);
  const eval::Map truth = {Wall(2.0, -2.0, 3.5), Wall(-3.0, -2.0, 2.0), corner};
  const ObservationCheck check = CheckLineObservations(path, RunConfig{}, truth);
  EXPECT_EQ(check.seen, (std::vector<char>{1, 0, 0}));
  fs::remove_all(fs::path(path).parent_path());
}

TEST(ObservationCheckTest, AStepBetweenParallelWallsIsSplitByTheFitTest) {
  const std::string path = WriteScans("step", 100, 0.05);
  const eval::Map truth = {Wall(2.0, -2.0, 2.0), Wall(2.05, 2.05, 3.6)};
  RunConfig config;
  const ObservationCheck with_test = CheckLineObservations(path, config, truth);
  EXPECT_GE(with_test.matched, 100);
  EXPECT_LT(with_test.mean_nis, 3.0);
  EXPECT_LT(with_test.max_nis, 40.0);
  // Without the test the two walls are one tilted line, far off its
  // covariance (and off both walls by up to centimetres).
  config.slam.features.fit_test_probability = 0.0;
  const ObservationCheck without = CheckLineObservations(path, config, truth);
  EXPECT_GT(without.mean_nis, 20.0);
  fs::remove_all(fs::path(path).parent_path());
}

TEST(ObservationCheckTest, ARealLogWithoutTruthIsRefusedNamingTheFile) {
  const fs::path dir = fs::temp_directory_path() / ("mjslam_observation_check_nan_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const RunConfig config;
  {
    std::ofstream out(dir / "scans.csv");
    out << "t,x,y,th";
    for (int b = 0; b < config.laser.num_beams; ++b) out << ",r" << b;
    out << "\n0,nan,nan,nan";
    for (int b = 0; b < config.laser.num_beams; ++b) out << ",2";
    out << "\n";
  }
  try {
    CheckLineObservations((dir / "scans.csv").string(), config, {});
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("scans.csv"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace mjslam::app
