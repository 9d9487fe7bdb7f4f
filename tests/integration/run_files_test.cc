// The run directory as an interface: files, determinism, replay, interrupts.
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "rundir/layout.h"
#include "rundir/run_files.h"
#include "tests/integration/run_helpers.h"

namespace mjslam::testing {
namespace {

using rundir::CsvTable;
using rundir::ReadCsv;

// A short run of the default config into `dir`.
int ShortRun(const std::string& dir, int seed, const std::string& extra = "") {
  return Shell(Program() + " run --quiet --no-render --config " + DefaultConfig() + " --duration 12 --seed " +
               std::to_string(seed) + " --out " + dir + " " + extra + " 2> " + dir + ".log");
}

// Same rows bit for bit (NaN equal to NaN).
void ExpectSameTable(const CsvTable& a, const CsvTable& b) {
  ASSERT_EQ(a.columns, b.columns);
  ASSERT_EQ(a.rows.size(), b.rows.size());
  for (std::size_t r = 0; r < a.rows.size(); ++r) {
    for (std::size_t c = 0; c < a.columns.size(); ++c) {
      const double x = a.rows[r][c];
      const double y = b.rows[r][c];
      if (std::isnan(x) && std::isnan(y)) continue;
      ASSERT_EQ(x, y) << a.path << " row " << r + 1 << " column " << a.columns[c];
    }
  }
}

class RunFilesTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    first_ = new std::string(FreshDir("first"));
    second_ = new std::string(FreshDir("second"));
    ASSERT_EQ(ShortRun(*first_, 5), 0) << ReadText(*first_ + ".log");
    ASSERT_EQ(ShortRun(*second_, 5), 0) << ReadText(*second_ + ".log");
  }
  static void TearDownTestSuite() {
    delete first_;
    delete second_;
  }
  static std::string* first_;
  static std::string* second_;
};
std::string* RunFilesTest::first_ = nullptr;
std::string* RunFilesTest::second_ = nullptr;

TEST_F(RunFilesTest, WritesEveryFileWithTheDocumentedColumns) {
  // Exactly the columns of rundir/layout.h (which tests/rundir/layout_test.cc
  // checks against docs/run_directory.md).
  const CsvTable trajectory = ReadCsv(rundir::PathIn(*first_, rundir::kTrajectoryFile));
  EXPECT_EQ(trajectory.columns, rundir::TrajectoryColumns());
  EXPECT_EQ(trajectory.columns[9], "explored");
  EXPECT_EQ(trajectory.columns.back(), "selective_processed");
  EXPECT_EQ(ReadCsv(rundir::PathIn(*first_, rundir::kExplorerFile), {"kind"}).columns, rundir::ExplorerColumns());
  // 12 s at 10 Hz: steps at t = 0, 0.1, ..., 12.
  ASSERT_EQ(trajectory.rows.size(), 121u);
  EXPECT_NEAR(trajectory.rows.back()[0], 12.0, 1e-9);

  const CsvTable scans = ReadCsv(rundir::PathIn(*first_, rundir::kScansFile));
  ASSERT_EQ(scans.columns, rundir::ScanColumns(181));
  EXPECT_EQ(scans.columns[4], "r0");
  EXPECT_EQ(scans.columns.back(), "r180");
  EXPECT_EQ(scans.rows.size(), 121u);
  for (const std::vector<double>& row : scans.rows) {
    for (std::size_t i = 4; i < row.size(); ++i) {
      ASSERT_GE(row[i], 0.0);
      ASSERT_LE(row[i], 30.0);
    }
  }

  for (const std::string map : {"map_classical.csv", "map_selective.csv"}) {
    const std::string text = ReadText(*first_ + "/" + map);
    EXPECT_EQ(text.substr(0, text.find('\n')), "id,type,p0,p1,c00,c01,c11,ax,ay,bx,by");
    EXPECT_EQ(text.substr(0, text.find('\n') + 1), rundir::HeaderLine(rundir::MapColumns()));
  }
  const nlohmann::json manifest = nlohmann::json::parse(ReadText(rundir::PathIn(*first_, rundir::kManifestFile)));
  EXPECT_EQ(manifest["status"], "completed");
  EXPECT_EQ(manifest["seed"], 5);
  EXPECT_EQ(manifest["mujoco_version"], "2.2.2");
  EXPECT_EQ(manifest["world_hash"].get<std::string>().substr(0, 8), "fnv1a64:");
  EXPECT_FALSE(manifest["end_time"].is_null());
  EXPECT_NE(ReadText(rundir::PathIn(*first_, rundir::kConfigFile)).find("seed: 5"), std::string::npos);
}

TEST_F(RunFilesTest, SameSeedGivesIdenticalFiles) {
  for (const std::string file : {"scans.csv", "map_classical.csv", "map_selective.csv",
                                 "config.yaml"}) {
    EXPECT_EQ(ReadText(*first_ + "/" + file), ReadText(*second_ + "/" + file)) << file;
  }
  // Trajectories agree bit for bit except the measured processing times.
  ExpectSameTable(DropColumns(ReadCsv(rundir::PathIn(*first_, rundir::kTrajectoryFile)), "_us"),
                  DropColumns(ReadCsv(rundir::PathIn(*second_, rundir::kTrajectoryFile)), "_us"));
  nlohmann::json a = nlohmann::json::parse(ReadText(rundir::PathIn(*first_, rundir::kManifestFile)));
  nlohmann::json b = nlohmann::json::parse(ReadText(rundir::PathIn(*second_, rundir::kManifestFile)));
  for (const char* key : {"start_time", "end_time", "command_line"}) {
    a.erase(key);
    b.erase(key);
  }
  EXPECT_EQ(a, b);
}

TEST_F(RunFilesTest, AnotherSeedGivesOtherNoise) {
  const std::string dir = FreshDir("other_seed");
  ASSERT_EQ(ShortRun(dir, 6), 0) << ReadText(dir + ".log");
  EXPECT_NE(ReadText(rundir::PathIn(*first_, rundir::kScansFile)), ReadText(rundir::PathIn(dir, rundir::kScansFile)));
}

TEST_F(RunFilesTest, ReplayReproducesTheFilters) {
  const std::string dir = FreshDir("replay");
  ASSERT_EQ(Shell(Program() + " replay --scans " + *first_ + "/scans.csv --config " +
                  *first_ + "/config.yaml --out " + dir + " 2> " + dir + ".log"),
            0)
      << ReadText(dir + ".log");
  ExpectSameTable(DropColumns(ReadCsv(rundir::PathIn(*first_, rundir::kTrajectoryFile)), "_us"),
                  DropColumns(ReadCsv(rundir::PathIn(dir, rundir::kTrajectoryFile)), "_us"));
  EXPECT_EQ(ReadText(rundir::PathIn(*first_, rundir::MapFile("selective"))), ReadText(rundir::PathIn(dir, rundir::MapFile("selective"))));
  EXPECT_EQ(ReadText(rundir::PathIn(*first_, rundir::MapFile("classical"))), ReadText(rundir::PathIn(dir, rundir::MapFile("classical"))));
}

// A realtime run (slam.timing: realtime, a cost model whose periods grow
// with the map) and its replay: the same trajectory bit for bit (but the
// measured times) and the same maps; summary.json counts each filter's
// processed and skipped scans as trajectory.csv's f_processed says.
TEST(RealtimeRunTest, ReplayReproducesARealtimeRunBitForBit) {
  const std::string run = FreshDir("realtime_run");
  ASSERT_EQ(ShortRun(run, 7,
                     "--set slam.timing=realtime --set control.model_s_per_update_per_n2=4e-5"),
            0)
      << ReadText(run + ".log");
  const std::string dir = FreshDir("realtime_replay");
  ASSERT_EQ(Shell(Program() + " replay --scans " + run + "/scans.csv --config " + run +
                  "/config.yaml --out " + dir + " 2> " + dir + ".log"),
            0)
      << ReadText(dir + ".log");
  const CsvTable trajectory = ReadCsv(rundir::PathIn(run, rundir::kTrajectoryFile));
  ExpectSameTable(DropColumns(trajectory, "_us"),
                  DropColumns(ReadCsv(rundir::PathIn(dir, rundir::kTrajectoryFile)), "_us"));
  for (const std::string& name : rundir::DefaultFilterNames()) {
    EXPECT_EQ(ReadText(rundir::PathIn(run, rundir::MapFile(name))),
              ReadText(rundir::PathIn(dir, rundir::MapFile(name))))
        << name;
  }

  const nlohmann::json summary =
      nlohmann::json::parse(ReadText(rundir::PathIn(run, rundir::kSummaryFile)));
  for (const std::string& name : rundir::DefaultFilterNames()) {
    const int column = trajectory.ColumnIndex(name + "_processed");
    int processed = 0;
    for (const std::vector<double>& row : trajectory.rows) processed += row[column] == 1.0 ? 1 : 0;
    const nlohmann::json& filter = summary["filters"][name];
    EXPECT_EQ(filter["scans_processed"].get<int>(), processed) << name;
    EXPECT_EQ(filter["scans_processed"].get<int>() + filter["scans_skipped"].get<int>(),
              static_cast<int>(trajectory.rows.size()))
        << name;
  }
  // The classical filter, slower, skips more (or the test proves nothing).
  EXPECT_GT(summary["filters"]["classical"]["scans_skipped"].get<int>(),
            summary["filters"]["selective"]["scans_skipped"].get<int>());
}

TEST(RunFailureTest, InterruptedRunKeepsCompleteRowsAndSaysSo) {
  const std::string dir = FreshDir("interrupted");
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const std::string program = Program();
    const std::string config = DefaultConfig();
    execl(program.c_str(), program.c_str(), "run", "--quiet", "--no-render", "--config", config.c_str(),
          "--duration", "100000", "--out", dir.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait until rows have reached the disk, then interrupt.
  const std::string trajectory = rundir::PathIn(dir, rundir::kTrajectoryFile);
  for (int i = 0; i < 600; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (std::filesystem::exists(trajectory) && std::filesystem::file_size(trajectory) > 200000) {
      break;
    }
  }
  kill(child, SIGINT);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  const nlohmann::json manifest = nlohmann::json::parse(ReadText(rundir::PathIn(dir, rundir::kManifestFile)));
  EXPECT_EQ(manifest["status"], "interrupted");
  const CsvTable rows = ReadCsv(trajectory);  // throws on a partial row
  EXPECT_GT(rows.rows.size(), 100u);
  EXPECT_EQ(manifest["steps"].get<std::size_t>(), rows.rows.size());
  EXPECT_NO_THROW(ReadCsv(rundir::PathIn(dir, rundir::kScansFile)));
}

TEST(RunFailureTest, MissingWorldIsAClearErrorAndNoRunIsStarted) {
  const std::string dir = FreshDir("missing_world");
  const int status = Shell(Program() + " run --quiet --no-render --config " + DefaultConfig() +
                           " --world /no/such/world.xml --out " + dir + "/run 2> " + dir +
                           "/err.log");
  EXPECT_EQ(status, 1);
  EXPECT_NE(ReadText(dir + "/err.log").find("/no/such/world.xml"), std::string::npos)
      << ReadText(dir + "/err.log");
  // Nothing written: a folder with a config.yaml and no manifest looked like
  // a run that never said how it ended.
  EXPECT_FALSE(std::filesystem::exists(dir + "/run"));
}

TEST(RunFailureTest, BadOverrideNamesTheKeyAndValue) {
  const std::string dir = FreshDir("bad_override");
  const int status = Shell(Program() + " run --quiet --no-render --config " + DefaultConfig() +
                           " --set laser.max_range_m=-4 --out " + dir + "/run 2> " + dir +
                           "/err.log");
  EXPECT_EQ(status, 1);
  const std::string err = ReadText(dir + "/err.log");
  EXPECT_NE(err.find("laser.max_range_m"), std::string::npos) << err;
  EXPECT_NE(err.find("-4"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/run/trajectory.csv"));
}

// Two writers into one run directory interleaved rows and mixed files: a
// directory held by another process is refused before anything is written.
TEST(RunFailureTest, RunDirectoryInUseIsRefusedAndLeftAlone) {
  const std::string dir = FreshDir("in_use");
  const std::string run = dir + "/run";
  {
    const rundir::RunDirectoryLock held(run);  // stands for a run still going
    std::ofstream(rundir::PathIn(run, rundir::kConfigFile)) << "the other run's config\n";
    const int status = Shell(Program() + " run --quiet --no-render --duration 1 --config " +
                             DefaultConfig() + " --out " + run + " 2> " + dir + "/err.log");
    EXPECT_EQ(status, 1);
    EXPECT_NE(ReadText(dir + "/err.log").find(run + ": in use by another mjslam process"),
              std::string::npos)
        << ReadText(dir + "/err.log");
    EXPECT_EQ(ReadText(rundir::PathIn(run, rundir::kConfigFile)), "the other run's config\n");
    EXPECT_FALSE(std::filesystem::exists(rundir::PathIn(run, rundir::kTrajectoryFile)));
  }
  // Released with its holder: the next run goes ahead.
  EXPECT_EQ(Shell(Program() + " run --quiet --no-render --duration 1 --config " + DefaultConfig() +
                  " --out " + run + " 2> " + dir + "/err2.log"),
            0)
      << ReadText(dir + "/err2.log");
}

// A negative seed wrapped to 2^64 - 1 and a huge duration overflowed the
// step count to a "completed" run of no steps; both are refused up front.
TEST(RunFailureTest, NegativeSeedAndHugeDurationAreRefused) {
  const std::string dir = FreshDir("bad_numbers");
  const std::string run = Program() + " run --quiet --no-render --config " + DefaultConfig() +
                          " --out " + dir + "/run ";
  EXPECT_NE(Shell(run + "--seed -1 2> " + dir + "/seed.log"), 0);
  EXPECT_NE(ReadText(dir + "/seed.log").find("--seed: expected a non-negative integer (got -1)"),
            std::string::npos)
      << ReadText(dir + "/seed.log");
  EXPECT_EQ(Shell(run + "--duration 1e12 2> " + dir + "/duration.log"), 1);
  EXPECT_NE(ReadText(dir + "/duration.log").find("run.duration_s: expected at most 1e8 control steps"),
            std::string::npos)
      << ReadText(dir + "/duration.log");
  EXPECT_FALSE(std::filesystem::exists(dir + "/run/trajectory.csv"));
}

}  // namespace
}  // namespace mjslam::testing
