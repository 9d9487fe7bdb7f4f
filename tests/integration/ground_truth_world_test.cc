// The ground truth of every shipped world against what the laser sees: every
// echo of a seeded 30 s run lies on a true line segment (or on a pillar),
// and every true feature lies on the walls' boundary.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "app/jobs/evaluate.h"
#include "app/engine/run_config.h"
#include "common/segments.h"
#include "sim/obstacles.h"
#include "sim/scene.h"
#include "tests/integration/run_helpers.h"
#include "rundir/layout.h"

namespace mjslam::testing {
namespace {

class GroundTruthWorldTest : public ::testing::TestWithParam<std::string> {};

TEST_P(GroundTruthWorldTest, EveryEchoLiesOnATrueSegmentOrAPillar) {
  const std::string world = std::string(MJSLAM_SOURCE_DIR) + "/worlds/" + GetParam() + ".xml";
  const std::string dir = FreshDir("truth_" + GetParam()) + "/run";
  ASSERT_EQ(Shell(Program() + " run --quiet --config " + DefaultConfig() + " --world " + world +
                  " --duration 30 --seed 5 --out " + dir + " 2> " + dir + ".log"),
            0)
      << ReadText(dir + ".log");
  const eval::Map truth = app::RunGroundTruth(dir);
  const app::RunConfig config = app::LoadRunConfig(rundir::PathIn(dir, rundir::kConfigFile), {});
  const sim::Scene scene(config.run.world, config.run.robot_model);
  std::vector<sim::ObstacleFootprint> pillars;
  for (const sim::ObstacleFootprint& o : scene.Obstacles()) {
    if (o.shape == sim::ObstacleFootprint::Shape::kCircle) pillars.push_back(o);
  }

  // Every true line's segment lies on its (r, al) line; every corner is the
  // end of two segments.
  int corners = 0;
  for (const MapFeature& f : truth) {
    if (f.type == MapFeature::Type::kLine) {
      const Eigen::Vector2d n(std::cos(f.params.y()), std::sin(f.params.y()));
      EXPECT_NEAR(n.dot(f.p_WA), f.params.x(), 1e-9);
      EXPECT_NEAR(n.dot(f.p_WB), f.params.x(), 1e-9);
      continue;
    }
    ++corners;
    int ends = 0;
    for (const MapFeature& g : truth) {
      if (g.type != MapFeature::Type::kLine) continue;
      if ((g.p_WA - f.params).norm() < 1e-9 || (g.p_WB - f.params).norm() < 1e-9) ++ends;
    }
    EXPECT_EQ(ends, 2) << "corner at " << f.params.transpose();
  }
  EXPECT_GE(corners, 4);

  // Echoes: the scan's ranges from the true laser pose. 5 mm range noise,
  // so within 3 cm of a true segment (or a pillar) for every echo.
  const rundir::CsvTable scans = rundir::ReadCsv(rundir::PathIn(dir, rundir::kScansFile));
  const double max_range = config.laser.max_range_m;
  int echoes = 0;
  int off = 0;
  double worst = 0.0;
  for (const std::vector<double>& row : scans.rows) {
    const Pose2 X_WS(row[1], row[2], row[3]);
    for (int i = 0; i < config.laser.num_beams; ++i) {
      const double range = row[4 + i];
      if (!(range < max_range)) continue;
      const double bearing = config.laser.AngleMinRad() + i * config.laser.AngleIncrementRad();
      const Eigen::Vector2d p_W = X_WS * Eigen::Vector2d(range * std::cos(bearing), range * std::sin(bearing));
      if (!pillars.empty() && sim::DistanceToObstacles(p_W, pillars) < 0.03) continue;
      double nearest = std::numeric_limits<double>::infinity();
      for (const MapFeature& f : truth) {
        if (f.type == MapFeature::Type::kLine) {
          nearest = std::min(nearest, PointSegmentDistance(p_W, f.p_WA, f.p_WB));
        }
      }
      ++echoes;
      worst = std::max(worst, nearest);
      if (nearest > 0.03) ++off;
    }
  }
  std::printf("%s: %zu features, %d echoes, %d off the true segments, worst %.4f m\n",
              GetParam().c_str(), truth.size(), echoes, off, worst);
  EXPECT_GT(echoes, 5000);
  EXPECT_EQ(off, 0);
}

INSTANTIATE_TEST_SUITE_P(ShippedWorlds, GroundTruthWorldTest,
                         ::testing::Values("room", "corridor_loop", "office", "pillars"));

}  // namespace
}  // namespace mjslam::testing
