// Monte Carlo regression tests on consistency: 25 seeded runs of 12 s of
// configs/default.yaml in the small room (worlds/room.xml; the robot drives
// the first, straight leg of the tour), through `mjslam sweep`, and the
// average pose NEES of each filter against the two-sided 95 % chi-square
// bounds for 25 runs, 3 dof ([2.118, 4.034]). Seeds 1..25 (run.seed = 1 plus
// the run index). And closed-loop explorer runs of the default world: 10 for
// the turns and the innovations, 25 under a condition of the envelope.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/engine/run_config.h"
#include "app/batch/sweep.h"
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

// The room sweep of kRuns runs of the default, with extra overrides.
nlohmann::json Sweep(const std::string& name, const std::vector<std::string>& extra) {
  std::vector<std::string> overrides = {
      "run.world=" + std::string(MJSLAM_SOURCE_DIR) + "/worlds/room.xml", "run.duration_s=12",
      "run.seed=1", "control.driver=tour"};
  overrides.insert(overrides.end(), extra.begin(), extra.end());
  return SweepOf(name, kRuns, overrides);
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

// The default's noise covers the envelope of robots it is meant for
// (docs/method.md, "The envelope"), so on one robot it may be
// underconfident, never overconfident: each filter's ANEES above its upper
// bound for <= 5 % of the steps, and not judged overconfident.
// Measured (seeds 1-25, 120 steps): above 0.000 / 0.000, mean ANEES 2.50 /
// 2.26 (classical / selective), underconfident; the check fails on the
// understated noise of the next test.
void ExpectNotOverconfident(const nlohmann::json& summary, const std::string& f) {
  const nlohmann::json& s = summary["filters"][f];
  EXPECT_GE(summary["sweep"]["steps"].get<int>(), 100);
  EXPECT_LE(s["fraction_above"].get<double>(), 0.05) << f;
  EXPECT_NE(s["verdict"], "overconfident") << f;
}

TEST_F(ConsistencyTest, SelectiveIsNeverOverconfident) {
  ExpectNotOverconfident(*summary_, "selective");
}

TEST_F(ConsistencyTest, ClassicalIsNeverOverconfident) {
  ExpectNotOverconfident(*summary_, "classical");
}

TEST(ConsistencyCheckTest, DetectsMeasurementNoiseUnderstatedTenTimes) {
  // The filters' model of the range noise and the line floors ten times too
  // small (laser.range_noise_std_m stays 0.005): the check must see both
  // filters overconfident. Measured: 0 steps inside, mean ANEES 262 and 297.
  // The extractor's fit test is off: it tests the points against the same
  // noise model, and ten times too small it splits every wall into pieces
  // too short to be lines (the filters then see almost nothing).
  const nlohmann::json summary =
      Sweep("understated", {"slam.features.range_noise_std_m=0.0005",
                            "slam.features.line_rho_floor_std_m=0.00001",
                            "slam.features.line_alpha_floor_std_deg=0.00025",
                            "slam.features.fit_test_probability=0"});
  for (const std::string f : {"classical", "selective"}) {
    const nlohmann::json& s = summary["filters"][f];
    EXPECT_LT(s["fraction_inside"].get<double>(), 0.2) << f;
    EXPECT_GT(s["fraction_above"].get<double>(), 0.8) << f;
    EXPECT_EQ(s["verdict"], "overconfident") << f;
  }
}

// The explorer's closed loop in the default world (the corridor loop) with
// the default, 25 runs, seeds 1..25, each until exploration ends. One sweep,
// two regression checks:
// - consistency: each filter's average NEES inside its 95 % bounds for at
//   least 80 % of the steps, above them (overconfident) for at most 15 %;
// - the innovations: the mean over the runs of each run's mean NIS of the
//   matched observations must lie in [1.5, 2.2] around the gate-truncated
//   2-dof chi-square mean 1.907.
// Measured (seeds 1-25): inside 0.892 / 0.882 (classical / selective), above
// 0.057 / 0.012, mean ANEES 3.57 / 3.03; mean NIS 1.592 / 1.605 (without the
// extractor's fit test and duplicate lines: inside 0.873 / 0.862, above
// 0.117 / 0.103). The
// understated noise of DetectsMeasurementNoiseUnderstatedTenTimes gives
// inside 0, above 1.
TEST(ClosedLoopConsistencyTest, TurnsAndInnovationsOfTheDefault) {
  const std::string dir = FreshDir("closed_loop");
  const nlohmann::json summary =
      SweepOf("closed_loop", 25, {"run.seed=1", "render.enabled=false"});
  EXPECT_GE(summary["sweep"]["steps"].get<int>(), 500);
  for (const std::string f : {"classical", "selective"}) {
    EXPECT_GE(summary["filters"][f]["fraction_inside"].get<double>(), 0.80) << f;
    EXPECT_LE(summary["filters"][f]["fraction_above"].get<double>(), 0.15) << f;
    double sum = 0.0;
    int runs = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir + "/runs")) {
      if (!entry.is_directory()) continue;
      const nlohmann::json run = rundir::ReadSummary(entry.path().string());
      sum += run["filters"][f]["innovation_check"]["mean_nis"].get<double>();
      ++runs;
    }
    ASSERT_EQ(runs, 25) << f;
    const double mean_nis = sum / runs;
    std::printf("closed_loop: %s: mean NIS over %d runs %.3f\n", f.c_str(), runs, mean_nis);
    EXPECT_GE(mean_nis, 1.5) << f;
    EXPECT_LE(mean_nis, 2.2) << f;
  }
}

// A condition of the envelope the default was not built on (docs/method.md,
// "The envelope"): the laser reads every range 15 mm long, the edge of a
// SICK's systematic error, in the corridor loop, 25 runs of the explorer,
// seeds 700-724, each until exploration ends. The default estimates the bias
// in its state: neither filter may be above its ANEES bound for more than
// 10 % of the steps, and each pooled pose component lies inside its 2-sigma
// band for >= 91 % of the steps. Measured (docs/results.md, "The envelope"):
// above 0.006 / 0.031, mean ANEES 2.81 / 3.11, 2-sigma 0.950-0.966.
// The same filters without self-calibration fail it on the same runs
// (measured: above 0.971 / 0.986, mean ANEES 339 / 308): the second test.
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

TEST(EnvelopeMonteCarloTest, WithoutSelfCalibrationTheFiltersFailIt) {
  std::vector<std::string> overrides = kRangeBias15mm;
  overrides.push_back(
      "slam.ekf.self_calibration={distance_scale_std: 0, heading_scale_std: 0, "
      "heading_per_m_std_rad: 0, range_bias_std_m: 0}");
  const nlohmann::json summary = SweepOf("envelope_bias_no_self_calibration", kRuns, overrides);
  for (const std::string f : {"classical", "selective"}) {
    EXPECT_FALSE(HoldsUnderTheBias(summary, f)) << f;
  }
}

}  // namespace
}  // namespace mjslam::testing
