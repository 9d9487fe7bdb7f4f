// mjslam evaluate, divergence and sweep on short runs of the room world: the
// files they write, merging into summary.json, errors, determinism of sweep
// runs against single runs, and resuming a sweep.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/jobs/evaluate.h"
#include "app/engine/run_config.h"
#include "app/batch/sweep.h"
#include "rundir/map_csv.h"
#include "tests/integration/run_helpers.h"
#include "rundir/layout.h"

namespace mjslam::testing {
namespace {

namespace fs = std::filesystem;

std::string Room() { return std::string(MJSLAM_SOURCE_DIR) + "/worlds/room.xml"; }

// A 10 s run of the room with seed `seed` into `dir`.
void RunRoom(const std::string& dir, int seed) {
  ASSERT_EQ(Shell(Program() + " run --quiet --config " + DefaultConfig() + " --world " + Room() +
                  " --duration 10 --seed " + std::to_string(seed) + " --out " + dir + " 2> " +
                  dir + ".log"),
            0)
      << ReadText(dir + ".log");
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

TEST(EvaluateTest, WritesGroundTruthAndMergesMetricsIntoSummary) {
  const std::string dir = FreshDir("evaluate") + "/run";
  RunRoom(dir, 3);
  // Another writer's key, to be kept.
  WriteText(rundir::PathIn(dir, rundir::kSummaryFile), R"({"run": {"duration_s": 10}, "filters": {"classical": {"processing_s": 1.5}}})");
  ASSERT_EQ(Shell(Program() + " evaluate " + dir + " --divergence-points 2000 > " + dir +
                  ".eval.log 2>&1"),
            0)
      << ReadText(dir + ".eval.log");

  // The room seen from inside: 4 lines (rho 3 or 4) and 4 corners.
  const eval::Map truth = rundir::ReadMapCsv(rundir::PathIn(dir, rundir::kGroundTruthMapFile));
  ASSERT_EQ(truth.size(), 8u);
  for (const MapFeature& f : truth) {
    if (f.type == MapFeature::Type::kLine) {
      EXPECT_TRUE(std::abs(f.params.x() - 3.0) < 1e-9 || std::abs(f.params.x() - 4.0) < 1e-9)
          << f.params.transpose();
    } else {
      EXPECT_NEAR(std::abs(f.params.x()), 4.0, 1e-9);
      EXPECT_NEAR(std::abs(f.params.y()), 3.0, 1e-9);
    }
  }
  const rundir::CsvTable table = rundir::ReadCsv(rundir::PathIn(dir, rundir::kGroundTruthMapFile), {"type"});
  EXPECT_EQ(table.columns, (std::vector<std::string>{"id", "type", "p0", "p1", "c00", "c01", "c11",
                                                      "ax", "ay", "bx", "by"}));

  const nlohmann::json summary = nlohmann::json::parse(ReadText(rundir::PathIn(dir, rundir::kSummaryFile)));
  EXPECT_EQ(summary["run"]["duration_s"], 10);
  EXPECT_EQ(summary["filters"]["classical"]["processing_s"], 1.5);
  for (const std::string f : {"classical", "selective"}) {
    const nlohmann::json& s = summary["filters"][f];
    for (const char* c : {"x", "y", "th"}) {
      EXPECT_GE(s["inside_2sigma"][c].get<double>(), 0.0);
      EXPECT_LE(s["inside_2sigma"][c].get<double>(), 1.0);
      EXPECT_LT(s["rmse"][c].get<double>(), 0.05) << f << " " << c;
    }
    EXPECT_GT(s["mean_nees"].get<double>(), 0.0);
    // In 10 s the robot sees the room's walls and corners, all of them true.
    EXPECT_GE(s["map"]["matched_truth"].get<int>(), 4) << f;
    EXPECT_EQ(s["map"]["unmatched_estimates"].get<int>(), 0) << f;
    EXPECT_EQ(s["map"]["num_truth"].get<int>(), 8);
  }
  EXPECT_EQ(summary["divergence"]["num_points"], 2000);
  EXPECT_GE(summary["divergence"]["classical_truth"].get<double>(), 0.0);
}

// --profile's stages: each charged once, together within the total; the
// divergence only when asked for.
TEST(EvaluateTest, ProfileChargesEachStage) {
  const std::string dir = FreshDir("evaluate_profile") + "/run";
  RunRoom(dir, 3);
  ASSERT_EQ(Shell(Program() + " evaluate " + dir + " --divergence-points 500 --profile > " + dir +
                  ".eval.log 2>&1"),
            0)
      << ReadText(dir + ".eval.log");
  EXPECT_NE(ReadText(dir + ".eval.log").find("cpu s: trajectory "), std::string::npos)
      << ReadText(dir + ".eval.log");
  for (const int points : {0, 2000}) {
    app::EvaluateOptions options;
    options.divergence_points = points;
    const app::EvaluationCpu cpu = app::EvaluateRunDirectory(dir, options).cpu;
    const double stages[] = {cpu.trajectory_s, cpu.ground_truth_s, cpu.poses_s, cpu.maps_s,
                             cpu.divergence_s, cpu.summary_s};
    double sum = 0.0;
    for (const double s : stages) {
      EXPECT_GE(s, 0.0);
      sum += s;
    }
    EXPECT_GT(cpu.ground_truth_s, 0.0);
    EXPECT_LE(sum, cpu.total_s);
    if (points == 0) {
      EXPECT_EQ(cpu.divergence_s, 0.0);
    } else {
      EXPECT_GT(cpu.divergence_s, 0.0);
    }
  }
}

TEST(EvaluateTest, BadInputsNameTheFileAndWriteNothing) {
  const std::string dir = FreshDir("evaluate_bad") + "/run";
  RunRoom(dir, 1);
  WriteText(rundir::PathIn(dir, rundir::kSummaryFile), "[1, 2]");
  EXPECT_EQ(Shell(Program() + " evaluate " + dir + " > " + dir + ".log 2>&1"), 1);
  EXPECT_NE(ReadText(dir + ".log").find("summary.json: expected a JSON object"),
            std::string::npos)
      << ReadText(dir + ".log");
  EXPECT_EQ(ReadText(rundir::PathIn(dir, rundir::kSummaryFile)), "[1, 2]");
  fs::remove(rundir::PathIn(dir, rundir::kSummaryFile));
  // A map with an unknown feature type.
  std::string map = ReadText(rundir::PathIn(dir, rundir::MapFile("selective")));
  map.replace(map.find(",line,"), 6, ",wall,");
  WriteText(rundir::PathIn(dir, rundir::MapFile("selective")), map);
  EXPECT_EQ(Shell(Program() + " evaluate " + dir + " > " + dir + ".log 2>&1"), 1);
  EXPECT_NE(ReadText(dir + ".log").find("map_selective.csv:2: type: expected line or corner (got 'wall')"),
            std::string::npos)
      << ReadText(dir + ".log");
  EXPECT_FALSE(fs::exists(rundir::PathIn(dir, rundir::kSummaryFile)));
  EXPECT_EQ(Shell(Program() + " evaluate " + dir + "/nowhere > " + dir + ".log 2>&1"), 1);
  EXPECT_NE(ReadText(dir + ".log").find("nowhere/manifest.json: missing"), std::string::npos)
      << ReadText(dir + ".log");
}

TEST(DivergenceCommandTest, WritesMeanAndVariancePerPointsAndPair) {
  const std::string dir = FreshDir("divergence") + "/run";
  RunRoom(dir, 2);
  ASSERT_EQ(Shell(Program() + " divergence " + dir + " --points 100 400 --realisations 4 2> " +
                  dir + ".log"),
            0)
      << ReadText(dir + ".log");
  const rundir::CsvTable table = rundir::ReadCsv(dir + "/divergence.csv", {"pair"});
  EXPECT_EQ(table.columns, (std::vector<std::string>{"num_points", "pair", "mean", "variance"}));
  ASSERT_EQ(table.rows.size(), 8u);
  EXPECT_EQ(table.text[0][0], "classical_selective");
  EXPECT_EQ(table.text[7][0], "selective_truth");
  EXPECT_EQ(table.rows[4][0], 400.0);
  for (const std::vector<double>& row : table.rows) {
    EXPECT_GE(row[2], 0.0);
    EXPECT_GT(row[3], 0.0);
  }
  // Seeded from the run's seed: the same file again.
  const std::string first = ReadText(dir + "/divergence.csv");
  ASSERT_EQ(Shell(Program() + " divergence " + dir + " --points 100 400 --realisations 4 --out " +
                  dir + "/again.csv 2> " + dir + ".log"),
            0);
  EXPECT_EQ(ReadText(dir + "/again.csv"), first);
}

// A run of four named filters, none called classical or selective: dr
// (dead reckoning, an empty map) and three EKFs a, b, c. The divergence
// compares the first two with a map (a, b), or the pair --pair names; its
// labels, summary.json's keys and the printed line go by those names.
TEST(DivergenceCommandTest, ComparesAPairOfFiltersByName) {
  const std::string dir = FreshDir("divergence_named") + "/run";
  ASSERT_EQ(Shell(Program() + " run --quiet --no-render --config " + DefaultConfig() +
                  " --world " + Room() + " --duration 6 --seed 2 --out " + dir +
                  " --set 'slam.filters=[{name: dr, kind: dead_reckoning}, {name: a, update: "
                  "classical}, {name: b, update: selective}, {name: c, update: classical, "
                  "process_noise_scale: 2}]' --set control.pose_source=b 2> " + dir + ".log"),
            0)
      << ReadText(dir + ".log");
  // The run's own evaluation: a and b (dr's map has nothing to compare).
  nlohmann::json summary = nlohmann::json::parse(ReadText(rundir::PathIn(dir, rundir::kSummaryFile)));
  for (const char* key : {"a_b", "b_a", "a_truth", "b_truth"}) {
    EXPECT_TRUE(summary["divergence"].contains(key)) << key << " " << summary["divergence"];
  }
  EXPECT_EQ(summary["divergence"].size(), 6u) << summary["divergence"];  // + num_points, realisations

  // --pair c a: the keys are c's and a's, replacing the last divergence.
  ASSERT_EQ(Shell(Program() + " evaluate " + dir + " --divergence-points 300 --pair c a > " + dir +
                  ".eval.log 2>&1"),
            0)
      << ReadText(dir + ".eval.log");
  summary = nlohmann::json::parse(ReadText(rundir::PathIn(dir, rundir::kSummaryFile)));
  EXPECT_EQ(summary["divergence"].size(), 6u) << summary["divergence"];
  for (const char* key : {"c_a", "a_c", "c_truth", "a_truth"}) {
    EXPECT_GE(summary["divergence"][key].get<double>(), 0.0) << key;
  }
  EXPECT_NE(ReadText(dir + ".eval.log").find("divergence: c||a "), std::string::npos)
      << ReadText(dir + ".eval.log");

  // mjslam divergence: a and b by default, then b and c.
  auto labels = [&dir](const std::string& options) {
    EXPECT_EQ(Shell(Program() + " divergence " + dir + " --points 100 --realisations 2 " +
                    options + " 2> " + dir + ".div.log"),
              0)
        << ReadText(dir + ".div.log");
    const rundir::CsvTable table = rundir::ReadCsv(dir + "/divergence.csv", {"pair"});
    std::vector<std::string> pairs;
    for (const std::vector<std::string>& text : table.text) pairs.push_back(text[0]);
    return pairs;
  };
  EXPECT_EQ(labels(""), (std::vector<std::string>{"a_b", "b_a", "a_truth", "b_truth"}));
  EXPECT_EQ(labels("--pair b c"), (std::vector<std::string>{"b_c", "c_b", "b_truth", "c_truth"}));

  // A pair the run has not, the same filter twice, or an empty map: errors
  // naming them, summary.json as it was.
  const std::string before = ReadText(rundir::PathIn(dir, rundir::kSummaryFile));
  for (const std::string command : {"evaluate", "divergence"}) {
    const std::string log = dir + "." + command + ".bad.log";
    EXPECT_EQ(Shell(Program() + " " + command + " " + dir + " --pair a x > " + log + " 2>&1"), 1);
    EXPECT_NE(ReadText(log).find("trajectory.csv: --pair: no filter x in the run (its filters: dr, "
                                 "a, b, c)"),
              std::string::npos)
        << ReadText(log);
    EXPECT_EQ(Shell(Program() + " " + command + " " + dir + " --pair b b > " + log + " 2>&1"), 1);
    EXPECT_NE(ReadText(log).find("--pair needs two different filters (got b twice)"),
              std::string::npos)
        << ReadText(log);
    EXPECT_NE(Shell(Program() + " " + command + " " + dir + " --pair a > " + log + " 2>&1"), 0);
    EXPECT_EQ(Shell(Program() + " " + command + " " + dir + " --pair dr a > " + log + " 2>&1"), 1);
    EXPECT_NE(ReadText(log).find("map_dr.csv, map_a.csv and the ground truth of config.yaml's "
                                 "world: divergence: the dr map has no corner and no line"),
              std::string::npos)
        << ReadText(log);
  }
  EXPECT_EQ(ReadText(rundir::PathIn(dir, rundir::kSummaryFile)), before);
}

class SweepTest : public ::testing::Test {
 protected:
  static app::RunConfig Config() {
    return app::LoadRunConfig(DefaultConfig(),
                              {"run.world=" + Room(), "run.duration_s=6", "run.seed=40"});
  }
  static app::SweepOptions Options(const std::string& dir) {
    app::SweepOptions options;
    options.runs = 3;
    options.jobs = 2;
    options.out_dir = dir;
    options.program = Program();
    options.verbose = false;
    return options;
  }
};

TEST_F(SweepTest, RunsAreBitIdenticalToSingleRunsAndTheAggregateIsWritten) {
  const std::string dir = FreshDir("sweep");
  const app::SweepResult result = app::RunSweep(Config(), Options(dir));
  EXPECT_EQ(result.runs_made, 3);
  // Run 2 has seed 42: the same files as a single run with seed 42.
  const std::string single = dir + "/single";
  ASSERT_EQ(Shell(Program() + " run --quiet --config " + DefaultConfig() + " --world " + Room() +
                  " --duration 6 --seed 42 --out " + single + " 2> " + single + ".log"),
            0);
  const std::string run = dir + "/runs/run_002";
  for (const char* file : {"config.yaml", "scans.csv", "map_classical.csv", "map_selective.csv"}) {
    EXPECT_EQ(ReadText(run + "/" + file), ReadText(single + "/" + file)) << file;
  }
  const rundir::CsvTable a = DropColumns(rundir::ReadCsv(rundir::PathIn(run, rundir::kTrajectoryFile)), "_us");
  const rundir::CsvTable b = DropColumns(rundir::ReadCsv(rundir::PathIn(single, rundir::kTrajectoryFile)), "_us");
  EXPECT_EQ(a.columns, b.columns);
  // Bit for bit; empty cells (NaN, e.g. f_nees at the known start) must be
  // empty in both.
  ASSERT_EQ(a.rows.size(), b.rows.size());
  for (std::size_t r = 0; r < a.rows.size(); ++r) {
    ASSERT_EQ(a.rows[r].size(), b.rows[r].size());
    for (std::size_t c = 0; c < a.rows[r].size(); ++c) {
      const double x = a.rows[r][c];
      const double y = b.rows[r][c];
      ASSERT_TRUE(x == y || (std::isnan(x) && std::isnan(y)))
          << "row " << r + 1 << " column " << a.columns[c] << ": " << x << " vs " << y;
    }
  }

  // nees.csv: a row per step with a defined NEES in every run (not the known
  // start, nor a step still at zero covariance), 3 runs each.
  const rundir::CsvTable nees = rundir::ReadCsv(dir + "/nees.csv");
  EXPECT_EQ(nees.columns, (std::vector<std::string>{"t", "classical_anees", "selective_anees",
                                                     "lower", "upper", "n_runs"}));
  EXPECT_GE(nees.rows.size(), 55u);
  EXPECT_LE(nees.rows.size(), 60u);
  EXPECT_EQ(nees.rows[0][5], 3.0);
  EXPECT_NEAR(nees.rows[0][3], 2.7004 / 3.0, 1e-3);  // chi2_9(0.025) / 3
  const nlohmann::json summary = nlohmann::json::parse(ReadText(rundir::PathIn(dir, rundir::kSummaryFile)));
  EXPECT_EQ(summary["sweep"]["completed_runs"], 3);
  EXPECT_TRUE(summary["filters"]["selective"]["processing_s"].get<double>() > 0.0);
  EXPECT_GE(summary["filters"]["selective"]["open_loop_s"].get<double>(), 0.0);
  EXPECT_TRUE(summary["filters"]["classical"]["runs_mean"]["map"]["matched_fraction"].is_number());
}

TEST_F(SweepTest, ResumesKeepingCompletedRunsAndRedoingTheOthers) {
  const std::string dir = FreshDir("sweep_resume");
  app::RunSweep(Config(), Options(dir));
  const std::string first_nees = ReadText(dir + "/nees.csv");
  // Run 0 completed: kept (its files untouched). Run 1 left unfinished: redone.
  // Run 2 completed but not evaluated: evaluated only.
  const auto time0 = fs::last_write_time(dir + "/runs/run_000/trajectory.csv");
  nlohmann::json manifest = nlohmann::json::parse(ReadText(dir + "/runs/run_001/manifest.json"));
  manifest["status"] = "interrupted";
  WriteText(dir + "/runs/run_001/manifest.json", manifest.dump());
  WriteText(dir + "/runs/run_001/stale_file", "x");
  fs::remove(dir + "/runs/run_002/summary.json");
  const auto time2 = fs::last_write_time(dir + "/runs/run_002/trajectory.csv");

  const app::SweepResult result = app::RunSweep(Config(), Options(dir));
  EXPECT_EQ(result.runs_kept, 2);
  EXPECT_EQ(result.runs_made, 1);
  EXPECT_EQ(fs::last_write_time(dir + "/runs/run_000/trajectory.csv"), time0);
  EXPECT_EQ(fs::last_write_time(dir + "/runs/run_002/trajectory.csv"), time2);
  EXPECT_TRUE(fs::exists(dir + "/runs/run_002/summary.json"));
  EXPECT_FALSE(fs::exists(dir + "/runs/run_001/stale_file"));
  EXPECT_EQ(nlohmann::json::parse(ReadText(dir + "/runs/run_001/manifest.json"))["status"],
            "completed");
  // The redone run is the same run: the aggregate is unchanged.
  EXPECT_EQ(ReadText(dir + "/nees.csv"), first_nees);

  // Another config in the same folder is refused.
  app::RunConfig other = Config();
  other.run.duration_s = 7.0;
  try {
    app::RunSweep(other, Options(dir));
    FAIL() << "expected an error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("config.yaml: this sweep directory was made with another config"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace mjslam::testing
