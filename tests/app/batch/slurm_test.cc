// The Slurm backend's submission without a cluster: a stand-in `sbatch` first
// in PATH records what it was given. The job script's #SBATCH lines, the plan,
// the job id, reading the submission back, and sbatch's refusal as an error.
// (The real cluster: tests/integration/slurm_sweep_test.cc, label slurm.)
#include "app/batch/slurm.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

namespace mjslam::app {
namespace {

namespace fs = std::filesystem;

std::string Read(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A folder with an executable `sbatch` that prints `output` and exits with
// `status`, put first in PATH for the test.
class SlurmSubmitTest : public ::testing::Test {
 protected:
  void Install(const std::string& output, int status) {
    bin_ = fs::temp_directory_path() / ("mjslam_fake_sbatch_" + std::to_string(::getpid()));
    fs::remove_all(bin_);
    fs::create_directories(bin_);
    std::ofstream(bin_ / "sbatch") << "#!/bin/sh\necho \"$@\" > " << (bin_ / "args").string()
                                   << "\necho '" << output << "'\nexit " << status << "\n";
    fs::permissions(bin_ / "sbatch", fs::perms::owner_all);
    old_path_ = std::getenv("PATH");
    ::setenv("PATH", (bin_.string() + ":" + old_path_).c_str(), 1);
  }
  void TearDown() override {
    if (!old_path_.empty()) ::setenv("PATH", old_path_.c_str(), 1);
    fs::remove_all(bin_);
  }
  static std::vector<PlannedRun> Runs(const fs::path& dir, int count) {
    std::vector<PlannedRun> runs;
    for (int i = 0; i < count; ++i) {
      runs.push_back({"/shared/sweep/config.yaml", static_cast<std::uint64_t>(10 + i),
                      (dir / ("run_" + std::to_string(i))).string(), RunStage::kRun});
    }
    return runs;
  }
  fs::path bin_;
  std::string old_path_;
};

TEST_F(SlurmSubmitTest, WritesTheJobScriptAndPlanAndReadsTheJobIdBack) {
  Install("4242;cluster", 0);
  const fs::path dir = bin_ / "sweep";
  RunPoolOptions pool;
  pool.program = "/shared/build/mjslam";
  pool.divergence_points = 500;
  SlurmOptions options;
  options.max_running = 2;
  options.partition = "short";
  options.time_limit = "00:10:00";
  options.memory = "2G";
  options.extra_options = {"--account=lab", "--qos=long"};
  options.runs_per_task = 2;
  const SlurmSubmission submitted = SubmitJobArray(Runs(dir, 5), pool, options, (dir / "slurm").string());
  EXPECT_EQ(submitted.job_id, "4242");
  EXPECT_EQ(submitted.tasks, 3);  // 5 runs, 2 per task
  EXPECT_EQ(submitted.folder, (dir / "slurm" / "submit_1").string());
  EXPECT_EQ(Read(bin_ / "args"), "--parsable " + submitted.folder + "/job.sh\n");

  const std::string script = Read(fs::path(submitted.folder) / "job.sh");
  for (const std::string& line : std::vector<std::string>{"#SBATCH --array=0-2%2\n", "#SBATCH --partition=short\n", "#SBATCH --time=00:10:00\n",
        "#SBATCH --mem=2G\n", "#SBATCH --account=lab\n", "#SBATCH --qos=long\n",
        "#SBATCH --output=" + submitted.folder + "/task_%a.log\n",
        "exec '/shared/build/mjslam' sweep-task '" + submitted.folder +
            "/plan.json' \"$SLURM_ARRAY_TASK_ID\"\n"}) {
    EXPECT_NE(script.find(line), std::string::npos) << line << "\nnot in\n" << script;
  }

  // Read back: the runs, their tasks' logs (run i in task i mod 3).
  const std::optional<SlurmSubmission> back = LatestSubmission((dir / "slurm").string());
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->job_id, "4242");
  ASSERT_EQ(back->runs.size(), 5u);
  EXPECT_EQ(back->runs[4].seed, 14u);
  EXPECT_EQ(back->runs[4].dir, (dir / "run_4").string());
  EXPECT_EQ(back->TaskLog(4), submitted.folder + "/task_1.log");

  // A second submission gets its own folder; the first one's stays.
  const SlurmSubmission again = SubmitJobArray(Runs(dir, 1), pool, SlurmOptions{}, (dir / "slurm").string());
  EXPECT_EQ(again.folder, (dir / "slurm" / "submit_2").string());
  EXPECT_NE(Read(fs::path(again.folder) / "job.sh").find("#SBATCH --array=0-0\n"), std::string::npos);
  EXPECT_TRUE(fs::exists(fs::path(submitted.folder) / "job.sh"));
}

TEST_F(SlurmSubmitTest, ARefusalIsAnErrorWithSbatchsMessage) {
  Install("sbatch: error: invalid partition specified: nosuch", 1);
  const fs::path dir = bin_ / "sweep";
  try {
    SubmitJobArray(Runs(dir, 2), RunPoolOptions{}, SlurmOptions{}, (dir / "slurm").string());
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("invalid partition specified: nosuch"),
              std::string::npos)
        << error.what();
  }
  // Nothing was submitted: no submission to wait for.
  EXPECT_FALSE(LatestSubmission((dir / "slurm").string()).has_value());
}

TEST_F(SlurmSubmitTest, MoreRunsThanAnArrayHoldsArePackedSeveralToATask) {
  Install("7", 0);
  const SlurmSubmission submitted =
      SubmitJobArray(Runs(bin_ / "sweep", 2500), RunPoolOptions{}, SlurmOptions{},
                     (bin_ / "sweep" / "slurm").string());
  EXPECT_EQ(submitted.tasks, 834);  // 3 runs per task: 2500 / 3 rounded up
  EXPECT_LE(submitted.tasks, kMaxArrayTasks);
}

}  // namespace
}  // namespace mjslam::app
