// Bad inputs and faults through the real command line (docs/reliability.md
// lists them with the test of each): damaged run files, numbers that
// overflow or slip through, a full disk, a stop request in a long phase, a
// resume beside a live run. Each must end in a clear one-line error (or exit
// 130 for a stop), leave no partial file and no crash.
#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/integration/run_helpers.h"

namespace mjslam::testing {
namespace {

namespace fs = std::filesystem;

// A 6 s run of the default world, made once; each test damages a copy.
class BadInputTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    base_ = FreshDir("bad_input") + "/base";
    const int status = Shell(Program() + " run --quiet --no-render --duration 6 --out " + base_ +
                             " 2> " + base_ + ".log");
    ASSERT_EQ(status, 0) << ReadText(base_ + ".log");
  }

  // A fresh copy of the base run named `name`.
  static std::string Copy(const std::string& name) {
    const std::string dir = fs::path(base_).parent_path() / name;
    fs::remove_all(dir);
    fs::copy(base_, dir);
    return dir;
  }

  // Runs `arguments` of mjslam; returns the exit status, stderr in `*message`.
  static int Mjslam(const std::string& arguments, std::string* message) {
    const std::string log = fs::path(base_).parent_path() / "command.log";
    const int status = Shell(Program() + " " + arguments + " > /dev/null 2> " + log);
    *message = ReadText(log);
    return status;
  }

  static std::string base_;
};

std::string BadInputTest::base_;

// Replaces line `line` (0 is the header) of a CSV file by `text`.
void ReplaceLine(const std::string& path, int line, const std::string& text) {
  std::vector<std::string> lines;
  {
    std::ifstream in(path);
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  lines.at(line) = text;
  std::ofstream out(path);
  for (const std::string& l : lines) out << l << "\n";
}

// Line `line` of a CSV file with field `field` replaced by `value`.
std::string WithField(const std::string& path, int line, int field, const std::string& value) {
  std::ifstream in(path);
  std::string l;
  for (int i = 0; i <= line; ++i) std::getline(in, l);
  std::vector<std::string> fields;
  std::string f;
  std::istringstream row(l);
  while (std::getline(row, f, ',')) fields.push_back(f);
  fields.at(field) = value;
  std::string joined;
  for (std::size_t i = 0; i < fields.size(); ++i) joined += (i ? "," : "") + fields[i];
  return joined;
}

int LineCount(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

TEST_F(BadInputTest, DamagedTrajectoryIsRefusedNamingFileLineAndValue) {
  struct Case {
    int field;
    std::string value;
    std::string expected;
  };
  // t, true_x, odom_th; times going backwards; 1e308 passes strtod but no building.
  const std::vector<Case> cases = {{0, "nan", "column t: expected a finite time (got nan)"},
                                   {0, "0", "column t: expected a time after the row before's"},
                                   {1, "nan", "column true_x: expected a number in"},
                                   {1, "1e308", "(got 1e+308)"},
                                   {6, "inf", "column odom_th"},
                                   {0, "1e999", "column t: expected a number (got '1e999')"}};
  for (const Case& c : cases) {
    const std::string dir = Copy("trajectory_" + std::to_string(c.field));
    const std::string path = dir + "/trajectory.csv";
    ReplaceLine(path, 3, WithField(path, 3, c.field, c.value));
    std::string message;
    // Every reader of the trajectory refuses it; replay (fast) for each case.
    std::vector<std::string> commands = {"replay --scans " + dir + "/scans.csv --out " + dir + "/replay"};
    if (&c == &cases.front()) {
      commands.push_back("evaluate " + dir);
      commands.push_back("render --no-video --no-plots --quiet " + dir);
    }
    for (const std::string& command : commands) {
      EXPECT_EQ(Mjslam(command, &message), 1) << command;
      EXPECT_NE(message.find(path + ":4: "), std::string::npos) << command << ": " << message;
      EXPECT_NE(message.find(c.expected), std::string::npos) << command << ": " << message;
      EXPECT_EQ(LineCount(message), 1) << message;
    }
  }
}

TEST_F(BadInputTest, FileCutInsideItsLastFieldIsRefused) {
  const std::string dir = Copy("cut");
  const std::string path = dir + "/trajectory.csv";
  const std::string text = ReadText(path);
  std::ofstream(path, std::ios::trunc) << text.substr(0, text.size() - 4);  // inside the last field
  std::string message;
  EXPECT_EQ(Mjslam("evaluate " + dir, &message), 1);
  EXPECT_NE(message.find(path + ":"), std::string::npos) << message;
  EXPECT_NE(message.find("cut short"), std::string::npos) << message;
}

TEST_F(BadInputTest, BadRangesAndAScansFileWithNoRowsAreRefused) {
  for (const std::string range : {"nan", "-0.5", "inf"}) {
    const std::string dir = Copy("ranges");
    const std::string path = dir + "/scans.csv";
    ReplaceLine(path, 2, WithField(path, 2, 10, range));
    std::string message;
    EXPECT_EQ(Mjslam("replay --scans " + path + " --out " + dir + "/replay", &message), 1);
    EXPECT_NE(message.find(path + ":3: column r6: expected a number in [0, 1e+06]"),
              std::string::npos)
        << message;
  }
  const std::string dir = Copy("no_scans");
  const std::string path = dir + "/scans.csv";
  const std::string header = ReadText(path).substr(0, ReadText(path).find('\n') + 1);
  std::ofstream(path, std::ios::trunc) << header;
  std::string message;
  EXPECT_EQ(Mjslam("replay --scans " + path + " --out " + dir + "/replay", &message), 1);
  EXPECT_NE(message.find(path + ": no rows"), std::string::npos) << message;
}

TEST_F(BadInputTest, RenderRefusesAVideoOfTooManyFrames) {
  const std::string dir = Copy("speedup");
  std::string message;
  EXPECT_EQ(Mjslam("render --no-plots --quiet --speedup 1e-6 " + dir, &message), 1);
  EXPECT_NE(message.find("render.speedup = 1e-06"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(dir + "/video.mp4"));
  // The run's video too, before the run starts.
  EXPECT_EQ(Mjslam("run --quiet --duration 6 --set render.enabled=true --set render.speedup=1e-6 "
                   "--out " + dir + "/run",
                   &message),
            1);
  EXPECT_NE(message.find("video frames"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(dir + "/run"));
}

TEST_F(BadInputTest, InfinityIsNoValueForAPositiveKey) {
  std::string message;
  EXPECT_EQ(Mjslam("config --set laser.max_range_m=.inf", &message), 1);
  EXPECT_NE(message.find("laser.max_range_m: expected a finite value > 0 (got inf)"),
            std::string::npos)
      << message;
}

TEST_F(BadInputTest, EmptyMapEvaluationNamesTheMapFile) {
  const std::string dir = Copy("empty_map");
  std::ofstream(dir + "/map_classical.csv", std::ios::trunc)
      << "id,type,p0,p1,c00,c01,c11,ax,ay,bx,by\n";
  std::string message;
  EXPECT_EQ(Mjslam("evaluate --divergence-points 100 " + dir, &message), 1);
  EXPECT_NE(message.find(dir + "/map_classical.csv"), std::string::npos) << message;
  EXPECT_NE(message.find("the classical map has no corner"), std::string::npos) << message;
}

TEST_F(BadInputTest, AFolderWithAnEmptyRunsFolderIsNoSweep) {
  const std::string dir = fs::path(base_).parent_path() / "not_a_sweep";
  fs::create_directories(dir + "/runs");
  std::string message;
  EXPECT_EQ(Mjslam("render " + dir, &message), 1);
  EXPECT_EQ(message.find("sweep report written"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(dir + "/index.html"));
}

// A full disk, as a file size limit (write() fails the same way): the run
// fails naming the CSV file, its manifest says failed, every file ends at a
// row boundary.
TEST_F(BadInputTest, FullDiskEndsFilesAtARowAndTheManifestSaysFailed) {
  const std::string dir = fs::path(base_).parent_path() / "full";
  fs::remove_all(dir);
  std::string message;
  const int status = Shell("bash -c \"trap '' XFSZ; ulimit -f 300; exec " + Program() +
                           " run --quiet --no-render --duration 60 --out " + dir + "\" 2> " + dir +
                           ".log");
  message = ReadText(dir + ".log");
  EXPECT_EQ(status, 1) << message;
  EXPECT_NE(message.find(".csv: write failed: File too large (the file ends at its last whole row)"),
            std::string::npos)
      << message;
  const nlohmann::json manifest = nlohmann::json::parse(ReadText(dir + "/manifest.json"));
  EXPECT_EQ(manifest["status"], "failed");
  EXPECT_NE(manifest["error"].get<std::string>().find(".csv: write failed"), std::string::npos);
  for (const char* file : {"trajectory.csv", "scans.csv", "explorer.csv"}) {
    const std::string text = ReadText(dir + "/" + file);
    ASSERT_FALSE(text.empty()) << file;
    EXPECT_EQ(text.back(), '\n') << file;
  }
}

// SIGTERM in the middle of a long divergence study: exit 130 within about a
// second, no divergence.csv and no temporary file.
TEST_F(BadInputTest, StopRequestEndsADivergenceStudyWithinASecond) {
  const std::string dir = Copy("stop");
  const std::string log = dir + ".log";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 2);
    ::execl(Program().c_str(), "mjslam", "divergence", dir.c_str(), "--points", "20000",
            "--realisations", "100000", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  const double stop_s = StopAfter(child, 1500, &status);
  std::printf("stopped %.3f s after SIGTERM\n", stop_s);
  ASSERT_TRUE(WIFEXITED(status)) << ReadText(log);
  EXPECT_EQ(WEXITSTATUS(status), 130) << ReadText(log);
  EXPECT_NE(ReadText(log).find("interrupted"), std::string::npos) << ReadText(log);
  EXPECT_FALSE(fs::exists(dir + "/divergence.csv"));
  EXPECT_FALSE(fs::exists(dir + "/divergence.csv.tmp"));
}

// A run of an earlier sweep still alive (here: a process holding its
// folder's lock): the resume refuses and leaves its files alone.
TEST_F(BadInputTest, SweepResumeRefusesToWriteWhereALiveRunWrites) {
  const std::string sweep = fs::path(base_).parent_path() / "sweep";
  fs::remove_all(sweep);
  std::string message;
  ASSERT_EQ(Mjslam("sweep --runs 1 --duration 2 --quiet --out " + sweep, &message), 0) << message;
  const std::string run = sweep + "/runs/run_000";
  // Make it look unfinished, and hold its lock as a live run would.
  nlohmann::json manifest = nlohmann::json::parse(ReadText(run + "/manifest.json"));
  manifest["status"] = "running";
  std::ofstream(run + "/manifest.json", std::ios::trunc) << manifest.dump();
  const pid_t holder = ::fork();
  ASSERT_GE(holder, 0);
  if (holder == 0) {
    const int fd = ::open(run.c_str(), O_RDONLY | O_DIRECTORY);
    if (fd < 0 || ::flock(fd, LOCK_EX) != 0) ::_exit(1);
    ::pause();  // until the test ends it
    ::_exit(0);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(Mjslam("sweep --runs 1 --duration 2 --quiet --out " + sweep, &message), 1);
  EXPECT_NE(message.find(run + ": in use by another mjslam process"), std::string::npos) << message;
  EXPECT_TRUE(fs::exists(run + "/trajectory.csv"));
  ::kill(holder, SIGTERM);
  ::waitpid(holder, nullptr, 0);
}

// A sweep killed with SIGKILL takes its runs with it: each child was linked
// to it (MJSLAM_STOP_WITH_PARENT, app::StopWithParent) and ends as on
// Ctrl-C, with whole rows and its manifest saying `interrupted`. Before, the
// children ran on, and a resume started the same seeds beside them.
TEST_F(BadInputTest, SweepKilledHardStopsItsRuns) {
  const std::string sweep = fs::path(base_).parent_path() / "killed_sweep";
  fs::remove_all(sweep);
  const std::string log = fs::path(base_).parent_path() / "killed_sweep.log";
  // Room tours of 3000 s: several seconds of CPU each, so both runs are alive
  // when the sweep is killed.
  const std::string command = "exec " + Program() + " sweep --runs 2 --jobs 2 --quiet --out " + sweep +
                              " --set run.world=" + std::string(MJSLAM_SOURCE_DIR) +
                              "/worlds/room.xml --set control.driver=tour --set run.duration_s=3000"
                              " --set render.enabled=false > " + log + " 2>&1";
  const pid_t parent = ::fork();
  ASSERT_GE(parent, 0);
  if (parent == 0) {
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // Wait until both runs have written rows, then kill the sweep outright.
  const std::vector<std::string> runs = {sweep + "/runs/run_000", sweep + "/runs/run_001"};
  auto rows_written = [&] {
    for (const std::string& run : runs) {
      if (!fs::exists(run + "/trajectory.csv") || fs::file_size(run + "/trajectory.csv") < 20000) return false;
    }
    return true;
  };
  for (int i = 0; i < 600 && !rows_written(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(rows_written()) << ReadText(log);
  ASSERT_EQ(::kill(parent, SIGKILL), 0);
  ::waitpid(parent, nullptr, 0);
  // Each run ends within seconds (it would take far longer to finish), and
  // says it was interrupted.
  auto stopped = [&] {
    for (const std::string& run : runs) {
      const nlohmann::json manifest = nlohmann::json::parse(ReadText(run + "/manifest.json"), nullptr, false);
      if (manifest.is_discarded() || manifest.value("status", "") == "running") return false;
    }
    return true;
  };
  for (int i = 0; i < 300 && !stopped(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(stopped());
  for (const std::string& run : runs) {
    const nlohmann::json manifest = nlohmann::json::parse(ReadText(run + "/manifest.json"));
    EXPECT_EQ(manifest.value("status", ""), "interrupted") << run;
  }
}

}  // namespace
}  // namespace mjslam::testing
