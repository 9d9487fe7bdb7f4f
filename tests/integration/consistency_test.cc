// Monte Carlo regression tests on consistency: 25 seeded runs of 12 s of
// configs/calibrated_corridor.yaml in the small room (worlds/room.xml; the robot drives the first, straight leg of
// the tour), through `mjslam sweep`, and the average pose NEES of each filter
// against the two-sided 95 % chi-square bounds for 25 runs, 3 dof
// ([2.118, 4.034]). Seeds 1..25 (run.seed = 1 plus the run index). And
// closed-loop explorer runs of the default world: 10 for the turns and the
// innovations, four draws of 25 for the calibrated target.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/run_config.h"
#include "app/sweep.h"
#include "rundir/summary.h"
#include "tests/integration/run_helpers.h"

namespace mjslam::testing {
namespace {

constexpr int kRuns = 25;

// Runs `runs` runs of the default config with `overrides` through the sweep
// and returns its summary.
nlohmann::json SweepOf(const std::string& name, int runs,
                       const std::vector<std::string>& overrides,
                       const std::string& config_path = DefaultConfig()) {
  const app::RunConfig config = app::LoadRunConfig(config_path, overrides);
  app::SweepOptions options;
  options.runs = runs;
  options.jobs = 2;
  options.out_dir = FreshDir(name);
  options.program = Program();
  options.verbose = false;
  options.evaluate_runs = false;  // the NEES is all the test needs
  const app::SweepResult result = app::RunSweep(config, options);
  EXPECT_EQ(result.runs_made, runs);
  for (const std::string f : {"classical", "selective"}) {
    const nlohmann::json& s = result.summary["filters"][f];
    std::printf("%s: %s: ANEES inside the bounds for %.3f of %d steps (above %.3f), mean ANEES "
                "%.3f, verdict %s\n",
                name.c_str(), f.c_str(), s["fraction_inside"].get<double>(),
                result.summary["sweep"]["steps"].get<int>(), s["fraction_above"].get<double>(),
                s["mean_anees"].get<double>(), s["verdict"].get<std::string>().c_str());
  }
  return result.summary;
}

// configs/calibrated_corridor.yaml: the robot without systematic errors and
// the filters' command model fitted to its true motion.
std::string CalibratedCorridorConfig() {
  return std::string(MJSLAM_SOURCE_DIR) + "/configs/calibrated_corridor.yaml";
}

// The room sweep of kRuns runs of configs/calibrated_corridor.yaml, with extra
// overrides. (The default, which predicts with the wheel odometry and
// estimates its errors, is underconfident on this 12 s leg: mean ANEES 1.95.)
nlohmann::json Sweep(const std::string& name, const std::vector<std::string>& extra) {
  std::vector<std::string> overrides = {
      "run.world=" + std::string(MJSLAM_SOURCE_DIR) + "/worlds/room.xml", "run.duration_s=12",
      "run.seed=1", "control.driver=tour"};
  overrides.insert(overrides.end(), extra.begin(), extra.end());
  return SweepOf(name, kRuns, overrides, CalibratedCorridorConfig());
}

class ConsistencyTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { summary_ = new nlohmann::json(Sweep("consistency", {})); }
  static void TearDownTestSuite() {
    delete summary_;
    summary_ = nullptr;
  }
  static nlohmann::json* summary_;
};
nlohmann::json* ConsistencyTest::summary_ = nullptr;

TEST_F(ConsistencyTest, SelectiveAverageNeesStaysInsideBoundsForMostSteps) {
  // Measured: 0.958 of 119 steps inside, mean ANEES 2.67.
  const nlohmann::json& s = (*summary_)["filters"]["selective"];
  EXPECT_GE((*summary_)["sweep"]["steps"].get<int>(), 100);
  EXPECT_GE(s["fraction_inside"].get<double>(), 0.9);
  EXPECT_EQ(s["verdict"], "consistent");
}

// Measured: 0.975 of 119 steps inside, mean ANEES 2.68. With corners of
// matched lines back in the correction (docs/method.md, departure 11) it
// fails: 0.76 inside, 0.24 above the upper bound, mean ANEES 3.75.
TEST_F(ConsistencyTest, ClassicalAverageNeesStaysInsideBoundsForMostSteps) {
  const nlohmann::json& s = (*summary_)["filters"]["classical"];
  EXPECT_GE(s["fraction_inside"].get<double>(), 0.9);
  EXPECT_EQ(s["verdict"], "consistent");
}

TEST(ConsistencyCheckTest, DetectsMeasurementNoiseUnderstatedTenTimes) {
  // The filters' model of the range noise and the line floors ten times too
  // small (laser.range_noise_std_m stays 0.005): the check must see both
  // filters overconfident. Measured: 0 steps inside, mean ANEES 273 and 320.
  const nlohmann::json summary =
      Sweep("understated", {"slam.features.range_noise_std_m=0.0005",
                            "slam.features.line_rho_floor_std_m=0.00001",
                            "slam.features.line_alpha_floor_std_deg=0.00025"});
  for (const std::string f : {"classical", "selective"}) {
    const nlohmann::json& s = summary["filters"][f];
    EXPECT_LT(s["fraction_inside"].get<double>(), 0.2) << f;
    EXPECT_GT(s["fraction_above"].get<double>(), 0.8) << f;
    EXPECT_EQ(s["verdict"], "overconfident") << f;
  }
}

// The explorer's closed loop in the default world (the corridor loop) with
// configs/calibrated_corridor.yaml (the drive disturbed by 1 % a step, wheel
// by wheel, and the process model fitted to that robot's true motion), 10 runs, seeds 1..10, each until exploration ends (about 150 s).
// One sweep, two checks:
// - the turns: neither filter's average NEES may go above its upper bound
//   (for the runs still going at that step) for more than 5 % of the steps.
//   Measured: 0.031 (classical) and 0.018 (selective) of 1470 steps above,
//   mean ANEES 3.20 and 2.92. Without the skid in the prediction
//   (slam.ekf.lateral_skid_s=0, docs/method.md departure 13) both filters
//   are above for 0.83 of the steps (mean ANEES 45 and 35); with the
//   conservative noise before the calibration, 0.108 (selective).
// - the innovations: the mean over the runs of each run's mean NIS of the
//   matched observations must lie in [1.6, 2.2] around the gate-truncated
//   2-dof chi-square mean 1.907 (measured 1.876 / 1.885). With the built-in
//   conservative command noise (0.03 + 10 %, change 0.5) it was 0.46 / 0.49
//   and the check fails. It does not see understated noise: with an earlier
//   fit and the slip x 0.3 the mean NIS was 1.90 / 1.99 while the pose NEES
//   was in the thousands (map and pose drift together).
TEST(ClosedLoopConsistencyTest, TurnsAndInnovationsOfTheDefault) {
  const std::string dir = FreshDir("closed_loop");
  const nlohmann::json summary =
      SweepOf("closed_loop", 10, {"run.seed=1", "render.enabled=false"},
              CalibratedCorridorConfig());
  EXPECT_GE(summary["sweep"]["steps"].get<int>(), 500);
  for (const std::string f : {"classical", "selective"}) {
    EXPECT_LE(summary["filters"][f]["fraction_above"].get<double>(), 0.05) << f;
    double sum = 0.0;
    int runs = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir + "/runs")) {
      if (!entry.is_directory()) continue;
      const nlohmann::json run = rundir::ReadSummary(entry.path().string());
      sum += run["filters"][f]["innovation_check"]["mean_nis"].get<double>();
      ++runs;
    }
    ASSERT_EQ(runs, 10) << f;
    const double mean_nis = sum / runs;
    std::printf("closed_loop: %s: mean NIS over %d runs %.3f\n", f.c_str(), runs, mean_nis);
    EXPECT_GE(mean_nis, 1.6) << f;
    EXPECT_LE(mean_nis, 2.2) << f;
  }
}

// The target of calibrated noise with configs/calibrated_corridor.yaml (the drive
// disturbed wheel by wheel, the process model fitted to that simulator's
// true motion on seeds 101-125): 25-run Monte Carlos of the explorer in the
// corridor loop, each run until exploration ends, with both filters' ANEES
// inside its 95 % bounds for >= 90 % of the steps and each pose component
// inside its 2-sigma band for 91-98.5 % of the pooled steps (neither over-
// nor underconfident). One draw of 25 runs spreads by about 0.03 around its
// mean (docs/results.md, "Calibrated process noise": ten draws), so a model
// at the target on average misses it on some draws. The test takes four
// draws (seeds 1-25, 26-50, 51-75, 76-100): the mean of their fractions
// inside the ANEES bounds >= 0.90 per filter, each draw >= 0.85, and every
// draw's pooled 2-sigma fractions inside [0.91, 0.985]. The same runs with
// the command noise understated (x 0.3) fail it: see the next test.
struct DrawFigures {
  double fraction_inside = 0.0;
  bool components_ok = true;
};

DrawFigures FiguresOf(const nlohmann::json& summary, const std::string& f) {
  EXPECT_GE(summary["sweep"]["steps"].get<int>(), 500);
  const nlohmann::json& s = summary["filters"][f];
  const nlohmann::json& inside = s["inside_2sigma_pooled"];
  std::printf("%s: ANEES inside %.3f, 2 sigma x %.3f y %.3f th %.3f\n", f.c_str(),
              s["fraction_inside"].get<double>(), inside["x"].get<double>(),
              inside["y"].get<double>(), inside["th"].get<double>());
  DrawFigures figures;
  figures.fraction_inside = s["fraction_inside"].get<double>();
  for (const std::string c : {"x", "y", "th"}) {
    figures.components_ok &= inside[c].get<double>() >= 0.91 && inside[c].get<double>() <= 0.985;
  }
  return figures;
}

TEST(CalibratedMonteCarloTest, BothFiltersAreConsistentInTheCorridor) {
  std::vector<nlohmann::json> draws;
  for (const int seed : {1, 26, 51, 76}) {
    draws.push_back(SweepOf("calibrated_target_" + std::to_string(seed), kRuns,
                            {"run.seed=" + std::to_string(seed), "render.enabled=false"},
                            CalibratedCorridorConfig()));
  }
  for (const std::string f : {"classical", "selective"}) {
    double sum = 0.0;
    for (const nlohmann::json& draw : draws) {
      const DrawFigures figures = FiguresOf(draw, f);
      sum += figures.fraction_inside;
      EXPECT_GE(figures.fraction_inside, 0.85) << f;
      EXPECT_TRUE(figures.components_ok) << f;
    }
    const double mean = sum / static_cast<double>(draws.size());
    std::printf("%s: ANEES inside over the four draws: mean %.3f\n", f.c_str(), mean);
    EXPECT_GE(mean, 0.90) << f;
  }
}

// The check can fail: the command noise understated (both factors 0.3), one
// draw. Measured: ANEES inside for none of the steps, above for all (mean
// ANEES in the thousands: the maps break).
TEST(CalibratedMonteCarloTest, UnderstatedNoiseMissesTheTarget) {
  const nlohmann::json summary =
      SweepOf("calibrated_understated", kRuns,
              {"run.seed=1", "render.enabled=false", "slam.ekf.command_noise.v_noise_scale=0.3",
               "slam.ekf.command_noise.w_noise_scale=0.3"},
              CalibratedCorridorConfig());
  for (const std::string f : {"classical", "selective"}) {
    const DrawFigures figures = FiguresOf(summary, f);
    EXPECT_FALSE(figures.fraction_inside >= 0.85 && figures.components_ok)
        << f << " meets the target with understated noise";
  }
}

// A condition of the envelope the default was not built on (docs/method.md,
// "The envelope"): the laser reads every range 15 mm long, the edge of a
// SICK's systematic error, in the corridor loop, 25 runs of the explorer,
// seeds 700-724, each until exploration ends. The default estimates the bias
// in its state: neither filter may be above its ANEES bound for more than
// 10 % of the steps, and each pooled pose component lies inside its 2-sigma
// band for >= 91 % of the steps. Measured (docs/results.md, "The envelope"):
// above 0.001 / 0.010, 2-sigma 0.965-0.987.
// configs/calibrated_corridor.yaml, the model fitted to the robot without
// systematic errors, fails it on the same runs (measured: above for most of
// the steps): the second test.
const std::vector<std::string> kRangeBias15mm = {"run.seed=700", "render.enabled=false",
                                                 "laser.range_bias_m=0.015",
                                                 "laser.range_bias_std_m=0"};

bool HoldsUnderTheBias(const nlohmann::json& summary, const std::string& f) {
  const nlohmann::json& s = summary["filters"][f];
  const nlohmann::json& inside = s["inside_2sigma_pooled"];
  bool ok = s["fraction_above"].get<double>() <= 0.10;
  for (const std::string c : {"x", "y", "th"}) ok &= inside[c].get<double>() >= 0.91;
  std::printf("%s: above %.3f, 2 sigma x %.3f y %.3f th %.3f: %s\n", f.c_str(),
              s["fraction_above"].get<double>(), inside["x"].get<double>(),
              inside["y"].get<double>(), inside["th"].get<double>(), ok ? "holds" : "fails");
  return ok;
}

TEST(EnvelopeMonteCarloTest, DefaultHoldsWithARangeBiasOf15mm) {
  const nlohmann::json summary = SweepOf("envelope_bias", kRuns, kRangeBias15mm);
  EXPECT_GE(summary["sweep"]["steps"].get<int>(), 500);
  for (const std::string f : {"classical", "selective"}) {
    EXPECT_TRUE(HoldsUnderTheBias(summary, f)) << f;
  }
}

TEST(EnvelopeMonteCarloTest, ModelFittedWithoutSystematicErrorsFailsIt) {
  const nlohmann::json summary =
      SweepOf("envelope_bias_calibrated_corridor", kRuns, kRangeBias15mm,
              CalibratedCorridorConfig());
  for (const std::string f : {"classical", "selective"}) {
    EXPECT_FALSE(HoldsUnderTheBias(summary, f)) << f;
  }
}

}  // namespace
}  // namespace mjslam::testing
