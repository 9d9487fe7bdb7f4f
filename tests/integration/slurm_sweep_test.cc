// The Slurm backend of `mjslam sweep` on a real, one-node Slurm cluster on
// this machine (scripts/slurm_localhost.sh, started and stopped by the ctest
// fixture `slurm_cluster`; label `slurm`): a sweep submitted as one job
// array, one array task cancelled with scancel, the failure listed with the
// task's Slurm log, a resume that submits only the missing run, and the
// result compared with the local backend's, file by file.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/engine/run_config.h"
#include "app/batch/slurm.h"
#include "app/batch/sweep.h"
#include "rundir/csv_reader.h"
#include "rundir/csv_writer.h"
#include "rundir/layout.h"
#include "tests/integration/run_helpers.h"

namespace mjslam::testing {
namespace {

namespace fs = std::filesystem;

constexpr int kRuns = 3;

// What a shell command printed on stdout, without the trailing newline.
std::string Output(const std::string& command) {
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(::popen(command.c_str(), "r"), ::pclose);
  std::string text;
  char buffer[256];
  while (pipe && std::fgets(buffer, sizeof(buffer), pipe.get()) != nullptr) text += buffer;
  while (!text.empty() && text.back() == '\n') text.pop_back();
  return text;
}

// Room tours of 600 s (about 3 s of CPU each): long enough that a task seen
// running is still running when it is cancelled (50 ms later at most). Tours
// of 40 s took 0.3 s once the laser and contacts became local, and a task
// could finish between squeue and scancel.
app::RunConfig Config() {
  return app::LoadRunConfig(DefaultConfig(),
                            {"run.world=" + std::string(MJSLAM_SOURCE_DIR) + "/worlds/room.xml",
                             "control.driver=tour", "render.enabled=false", "run.duration_s=600",
                             "run.seed=7"});
}

app::SweepOptions Options(const std::string& dir, app::SweepBackend backend) {
  app::SweepOptions options;
  options.runs = kRuns;
  options.jobs = 2;
  options.out_dir = dir;
  options.program = Program();
  options.verbose = false;
  options.backend = backend;
  options.slurm.max_running = 1;  // one task at a time: one can be caught running
  options.slurm.poll_s = 0.2;
  options.slurm.extra_options = {"--job-name=mjslam-test"};
  return options;
}

// The first task of job `job_id` seen running (squeue), or "" after 60 s.
std::string RunningTask(const std::string& job_id) {
  for (int i = 0; i < 1200; ++i) {
    const std::string task = Output("squeue -h -r -t RUNNING -o %i -j " + job_id + " 2>/dev/null");
    if (!task.empty()) return task.substr(0, task.find('\n'));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return "";
}

// A table as text, each value in shortest round-trip form (NaN included).
std::string TableText(const rundir::CsvTable& table) {
  std::string text;
  for (const std::string& c : table.columns) text += c + ",";
  for (const std::vector<double>& row : table.rows) {
    text += "\n";
    for (const double v : row) text += rundir::FormatDouble(v) + ",";
  }
  return text;
}

// Every file of the two run directories is the same, except the manifest
// (times, command line) and trajectory.csv's measured times (*_us).
void ExpectSameRun(const std::string& local, const std::string& slurm) {
  int compared = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(local)) {
    const std::string name = entry.path().filename().string();
    const std::string other = slurm + "/" + name;
    ASSERT_TRUE(fs::exists(other)) << other;
    if (name == rundir::kManifestFile) continue;
    if (name == rundir::kTrajectoryFile) {
      const std::string a = TableText(DropColumns(rundir::ReadCsv(entry.path().string()), "_us"));
      EXPECT_TRUE(a == TableText(DropColumns(rundir::ReadCsv(other), "_us"))) << other;
    } else {
      EXPECT_TRUE(ReadText(entry.path().string()) == ReadText(other)) << other;
    }
    ++compared;
  }
  EXPECT_GE(compared, 6);
}

TEST(SlurmSweepTest, ACancelledTaskIsListedResumedAndTheResultIsTheLocalOne) {
  ASSERT_EQ(Shell("sinfo -h > /dev/null"), 0) << "no Slurm cluster (SLURM_CONF=" +
                                                    std::string(std::getenv("SLURM_CONF") ? std::getenv("SLURM_CONF") : "") + ")";
  const std::string root = FreshDir("slurm_sweep");
  const std::string local_dir = root + "/local";
  const std::string slurm_dir = root + "/slurm";

  // Submit without waiting; cancel the first task seen running.
  app::SweepOptions slurm = Options(slurm_dir, app::SweepBackend::kSlurm);
  slurm.wait = false;
  const app::SweepResult submitted = app::RunSweep(Config(), slurm);
  ASSERT_TRUE(submitted.submitted);
  ASSERT_FALSE(submitted.job_id.empty());
  const std::string task = RunningTask(submitted.job_id);
  ASSERT_FALSE(task.empty()) << "no task of job " << submitted.job_id << " ran within 60 s";
  ASSERT_EQ(Shell("scancel " + task), 0);
  const std::string task_index = task.substr(task.find('_') + 1);
  std::printf("job %s: cancelled task %s\n", submitted.job_id.c_str(), task.c_str());

  // Finishing it lists the cancelled task's run with the task's Slurm log.
  try {
    app::AggregateSweepDirectory(slurm_dir, Options(slurm_dir, app::SweepBackend::kSlurm));
    ADD_FAILURE() << "a sweep with a cancelled task was aggregated";
  } catch (const std::runtime_error& error) {
    const std::string message = error.what();
    std::printf("%s\n", message.c_str());
    EXPECT_NE(message.find("1 of " + std::to_string(kRuns) + " runs failed"), std::string::npos);
    const std::string log = slurm_dir + "/slurm/submit_1/task_" + task_index + ".log";
    EXPECT_NE(message.find(log), std::string::npos) << message;
    EXPECT_NE(ReadText(log).find("CANCELLED"), std::string::npos) << ReadText(log);
  }
  EXPECT_FALSE(fs::exists(slurm_dir + "/summary.json"));

  // The resume submits the one run left and waits for it.
  const app::SweepResult resumed =
      app::RunSweep(Config(), Options(slurm_dir, app::SweepBackend::kSlurm));
  EXPECT_EQ(resumed.runs_made, 1);
  EXPECT_EQ(resumed.runs_kept, kRuns - 1);
  const std::optional<app::SlurmSubmission> second = app::LatestSubmission(slurm_dir + "/slurm");
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(second->runs.size(), 1u);
  EXPECT_NE(second->job_id, submitted.job_id);
  EXPECT_NE(ReadText(second->folder + "/job.sh").find("#SBATCH --job-name=mjslam-test"),
            std::string::npos);

  // The same sweep on the local backend: the same files, measured times aside.
  const app::SweepResult local = app::RunSweep(Config(), Options(local_dir, app::SweepBackend::kLocal));
  EXPECT_TRUE(ReadText(local_dir + "/nees.csv") == ReadText(slurm_dir + "/nees.csv"));
  nlohmann::json a = local.summary["filters"];
  nlohmann::json b = resumed.summary["filters"];
  for (const std::string& f : rundir::DefaultFilterNames()) {
    a[f].erase("measured_processing_s");
    b[f].erase("measured_processing_s");
  }
  EXPECT_EQ(a, b);
  for (int i = 0; i < kRuns; ++i) {
    char name[16];
    std::snprintf(name, sizeof(name), "run_%03d", i);
    ExpectSameRun(local_dir + "/runs/" + name, slurm_dir + "/runs/" + name);
  }
}

}  // namespace
}  // namespace mjslam::testing
