#include "app/batch/slurm.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <thread>

#include <nlohmann/json.hpp>

#include "rundir/manifest.h"
#include "rundir/run_files.h"

namespace mjslam::app {
namespace {

namespace fs = std::filesystem;

constexpr char kPlanFile[] = "plan.json";
constexpr char kJobScriptFile[] = "job.sh";
constexpr char kJobIdFile[] = "job_id";
constexpr char kSubmitPrefix[] = "submit_";

// What a command printed (stdout and stderr together) and its exit status.
struct CommandOutput {
  int status = -1;
  std::string text;
};

// Runs `argv` (searched in PATH) and collects its output. Throws when it
// cannot be started (e.g. Slurm is not installed here).
CommandOutput Capture(const std::vector<std::string>& argv) {
  int pipe_fds[2];
  if (::pipe(pipe_fds) != 0) throw std::runtime_error("pipe: " + std::string(std::strerror(errno)));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDERR_FILENO);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);
  pid_t pid = -1;
  try {
    pid = StartProcess(argv, actions, true);
  } catch (const std::runtime_error& error) {
    posix_spawn_file_actions_destroy(&actions);
    ::close(pipe_fds[0]);
    ::close(pipe_fds[1]);
    throw std::runtime_error(std::string(error.what()) + ": is Slurm installed and in PATH?");
  }
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipe_fds[1]);
  CommandOutput output;
  char buffer[4096];
  for (ssize_t n; (n = ::read(pipe_fds[0], buffer, sizeof(buffer))) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) break;
    output.text.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(pipe_fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  output.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return output;
}

// `text` without trailing white space.
std::string Trimmed(std::string text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.pop_back();
  return text;
}

// `text` quoted for bash.
std::string ShellQuoted(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

nlohmann::json PlanJson(const std::vector<PlannedRun>& runs, const RunPoolOptions& pool, int tasks) {
  nlohmann::json plan;
  plan["program"] = pool.program;
  plan["evaluate_runs"] = pool.evaluate_runs;
  plan["divergence_points"] = pool.divergence_points;
  plan["tasks"] = tasks;
  plan["runs"] = nlohmann::json::array();
  for (const PlannedRun& run : runs) {
    plan["runs"].push_back({{"config", run.config_path}, {"seed", run.seed}, {"dir", run.dir}});
  }
  return plan;
}

// The job script: every setting as an #SBATCH line, so that the file alone
// says what was submitted (and can be submitted again by hand).
std::string JobScript(const SlurmSubmission& submission, const RunPoolOptions& pool,
                      const SlurmOptions& options) {
  std::string script = "#!/bin/bash\n# Written by mjslam sweep --backend slurm.\n";
  script += "#SBATCH --job-name=mjslam-sweep\n";
  script += "#SBATCH --array=0-" + std::to_string(submission.tasks - 1) +
            (options.max_running > 0 ? "%" + std::to_string(options.max_running) : "") + "\n";
  script += "#SBATCH --output=" + (fs::path(submission.folder) / "task_%a.log").string() + "\n";
  script += "#SBATCH --chdir=" + fs::current_path().string() + "\n";
  script += "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n";
  if (!options.partition.empty()) script += "#SBATCH --partition=" + options.partition + "\n";
  if (!options.time_limit.empty()) script += "#SBATCH --time=" + options.time_limit + "\n";
  if (!options.memory.empty()) script += "#SBATCH --mem=" + options.memory + "\n";
  for (const std::string& extra : options.extra_options) script += "#SBATCH " + extra + "\n";
  script += "exec " + ShellQuoted(pool.program) + " sweep-task " +
            ShellQuoted((fs::path(submission.folder) / kPlanFile).string()) +
            " \"$SLURM_ARRAY_TASK_ID\"\n";
  return script;
}

}  // namespace

std::string SlurmSubmission::TaskLog(std::size_t index) const {
  return (fs::path(folder) / ("task_" + std::to_string(index % static_cast<std::size_t>(tasks)) +
                              ".log"))
      .string();
}

SlurmSubmission SubmitJobArray(const std::vector<PlannedRun>& runs, const RunPoolOptions& pool,
                               const SlurmOptions& options, const std::string& slurm_dir) {
  if (runs.empty()) throw std::runtime_error("slurm: nothing to submit");
  SlurmSubmission submission;
  submission.runs = runs;
  // Enough runs per task to stay inside Slurm's default array size.
  const int count = static_cast<int>(runs.size());
  const int per_task = std::max(options.runs_per_task, (count + kMaxArrayTasks - 1) / kMaxArrayTasks);
  submission.tasks = (count + per_task - 1) / per_task;

  // A new folder per submission: the logs of earlier ones stay.
  rundir::MakeRunDirectory(slurm_dir);
  int number = 1;
  while (fs::exists(fs::path(slurm_dir) / (kSubmitPrefix + std::to_string(number)))) ++number;
  submission.folder = fs::absolute(fs::path(slurm_dir) / (kSubmitPrefix + std::to_string(number)))
                          .lexically_normal()
                          .string();
  rundir::MakeRunDirectory(submission.folder);
  rundir::WriteFileAtomically((fs::path(submission.folder) / kPlanFile).string(),
                              PlanJson(runs, pool, submission.tasks).dump(1) + "\n");
  const std::string script_path = (fs::path(submission.folder) / kJobScriptFile).string();
  rundir::WriteFileAtomically(script_path, JobScript(submission, pool, options));

  // sbatch --parsable prints "<job id>[;<cluster>]".
  const CommandOutput output = Capture({"sbatch", "--parsable", script_path});
  if (output.status != 0) {
    throw std::runtime_error("sbatch " + script_path + " failed (exit status " +
                             std::to_string(output.status) + "): " + Trimmed(output.text));
  }
  const std::string text = Trimmed(output.text);
  const std::string last_line = text.substr(text.find_last_of('\n') + 1);
  submission.job_id = last_line.substr(0, last_line.find(';'));
  if (submission.job_id.empty() ||
      submission.job_id.find_first_not_of("0123456789") != std::string::npos) {
    throw std::runtime_error("sbatch " + script_path + ": no job id in its output '" + text + "'");
  }
  rundir::WriteFileAtomically((fs::path(submission.folder) / kJobIdFile).string(),
                              submission.job_id + "\n");
  return submission;
}

std::optional<SlurmSubmission> LatestSubmission(const std::string& slurm_dir) {
  int number = 1;
  while (fs::exists(fs::path(slurm_dir) / (kSubmitPrefix + std::to_string(number)))) ++number;
  if (number == 1) return std::nullopt;
  SlurmSubmission submission;
  submission.folder = fs::absolute(fs::path(slurm_dir) / (kSubmitPrefix + std::to_string(number - 1)))
                          .lexically_normal()
                          .string();
  const std::string id_path = (fs::path(submission.folder) / kJobIdFile).string();
  // A folder without a job id: sbatch refused it; nothing of it runs.
  if (!fs::exists(id_path)) return std::nullopt;
  submission.job_id = Trimmed(rundir::ReadTextFile(id_path));
  const nlohmann::json plan =
      rundir::ReadJsonFile((fs::path(submission.folder) / kPlanFile).string(), nullptr);
  submission.tasks = plan.at("tasks").get<int>();
  for (const nlohmann::json& run : plan.at("runs")) {
    submission.runs.push_back({run.at("config").get<std::string>(),
                               run.at("seed").get<std::uint64_t>(),
                               run.at("dir").get<std::string>(), RunStage::kRun});
  }
  return submission;
}

bool JobInQueue(const std::string& job_id) {
  const CommandOutput output = Capture({"squeue", "-h", "-j", job_id, "-o", "%i %T"});
  if (output.status == 0) return !Trimmed(output.text).empty();
  // A job that left the controller's memory (MinJobAge) is no longer known.
  if (output.text.find("Invalid job id") != std::string::npos) return false;
  throw std::runtime_error("squeue -j " + job_id + " failed (exit status " +
                           std::to_string(output.status) + "): " + Trimmed(output.text));
}

bool WaitForJob(const std::string& job_id, double poll_s,
                const volatile std::sig_atomic_t* stop_requested) {
  const auto tick = std::chrono::milliseconds(100);
  while (JobInQueue(job_id)) {
    for (double waited = 0.0; waited < poll_s; waited += 0.1) {
      if (stop_requested != nullptr && *stop_requested != 0) return false;
      std::this_thread::sleep_for(tick);
    }
  }
  return true;
}

RunPoolResult RunSweepTask(const std::string& plan_path, int task,
                           const volatile std::sig_atomic_t* stop_requested) {
  const nlohmann::json plan = rundir::ReadJsonFile(plan_path, nullptr);
  if (!plan.is_object() || !plan.contains("runs") || !plan.contains("tasks")) {
    throw std::runtime_error(plan_path + ": not a sweep plan (no 'runs' or 'tasks')");
  }
  const int tasks = plan.at("tasks").get<int>();
  if (task < 0 || task >= tasks) {
    throw std::runtime_error(plan_path + ": task " + std::to_string(task) + " out of range [0, " +
                             std::to_string(tasks - 1) + "]");
  }
  RunPoolOptions pool;
  pool.program = plan.at("program").get<std::string>();
  pool.evaluate_runs = plan.at("evaluate_runs").get<bool>();
  pool.divergence_points = plan.at("divergence_points").get<int>();
  pool.stop_requested = stop_requested;
  // This task's share, each planned again (a requeued task finds its
  // completed runs).
  std::deque<PlannedRun> pending;
  const nlohmann::json& runs = plan.at("runs");
  for (std::size_t i = static_cast<std::size_t>(task); i < runs.size();
       i += static_cast<std::size_t>(tasks)) {
    PlannedRun run{runs[i].at("config").get<std::string>(), runs[i].at("seed").get<std::uint64_t>(),
                   runs[i].at("dir").get<std::string>(), RunStage::kRun};
    if (PlanRun(pool.evaluate_runs, &run)) pending.push_back(run);
  }
  return RunPool(pending, 1, pool);
}

}  // namespace mjslam::app
