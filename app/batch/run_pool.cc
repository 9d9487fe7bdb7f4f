#include "app/batch/run_pool.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <thread>

#include <nlohmann/json.hpp>

#include "rundir/layout.h"
#include "rundir/manifest.h"
#include "rundir/run_files.h"

extern char** environ;

namespace mjslam::app {
namespace {

namespace fs = std::filesystem;
using rundir::PathIn;

// Starts `argv` with stdout and stderr appended to `log_path`, and
// kStopWithParentVariable set to this process's id: the child stops (as on
// SIGTERM) when the sweep dies, even by SIGKILL (StopWithParent).
pid_t Spawn(const std::vector<std::string>& argv, const std::string& log_path) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(),
                                   O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  try {
    const pid_t pid = StartProcess(argv, actions, false, true);
    posix_spawn_file_actions_destroy(&actions);
    return pid;
  } catch (...) {
    posix_spawn_file_actions_destroy(&actions);
    throw;
  }
}

// A run in the pool and its process.
struct ActiveRun {
  PlannedRun run;
  pid_t pid = -1;
};

// Starts the process of `run`'s stage: `mjslam run` or `mjslam evaluate`.
pid_t Start(const PlannedRun& run, const RunPoolOptions& options) {
  if (run.stage == RunStage::kRun) {
    return Spawn({options.program, "run", "--quiet", "--no-render", "--no-evaluate", "--config",
                  run.config_path, "--seed", std::to_string(run.seed), "--out", run.dir},
                 run.dir + ".log");
  }
  return Spawn({options.program, "evaluate", run.dir, "--divergence-points",
                std::to_string(options.divergence_points)},
               run.dir + ".log");
}

double CpuSeconds(const struct rusage& usage) {
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

}  // namespace

pid_t StartProcess(const std::vector<std::string>& argv, const posix_spawn_file_actions_t& actions,
                   bool search_path, bool stop_with_parent) {
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  // The environment: this process's, less any inherited parent link, plus
  // the link to this process when asked.
  const std::string prefix = std::string(kStopWithParentVariable) + "=";
  const std::string link = prefix + std::to_string(::getpid());
  std::vector<char*> env;
  for (char** e = environ; *e != nullptr; ++e) {
    if (std::strncmp(*e, prefix.c_str(), prefix.size()) != 0) env.push_back(*e);
  }
  if (stop_with_parent) env.push_back(const_cast<char*>(link.c_str()));
  env.push_back(nullptr);
  pid_t pid = -1;
  const int error = search_path
                        ? posix_spawnp(&pid, argv[0].c_str(), &actions, nullptr, args.data(), env.data())
                        : posix_spawn(&pid, argv[0].c_str(), &actions, nullptr, args.data(), env.data());
  if (error != 0) {
    throw std::runtime_error("cannot start '" + argv[0] + "': " + std::strerror(error));
  }
  return pid;
}

void StopWithParent(void (*stop)(int)) {
  const char* value = std::getenv(kStopWithParentVariable);
  if (value == nullptr) return;
  char* end = nullptr;
  const long parent = std::strtol(value, &end, 10);
  ::unsetenv(kStopWithParentVariable);  // not inherited by this process's children
  if (end == value || *end != '\0' || parent <= 0) return;
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  // The parent may have died before the line above: then stop now.
  if (::getppid() != static_cast<pid_t>(parent)) stop(SIGTERM);
}

bool IsCompletedRun(const std::string& dir, bool* evaluated) {
  nlohmann::json manifest;
  nlohmann::json summary;
  try {
    manifest = rundir::ReadJsonFile(PathIn(dir, rundir::kManifestFile), nullptr);
    summary = rundir::ReadJsonFile(PathIn(dir, rundir::kSummaryFile), nullptr);
  } catch (const std::runtime_error&) {
    return false;  // a file cut short: redo the run
  }
  if (!manifest.is_object() || manifest.value("status", "") != "completed") return false;
  // Evaluated: every filter of the run (whatever their names) has its metrics.
  *evaluated = summary.is_object() && summary.contains("filters") &&
               summary["filters"].is_object() && !summary["filters"].empty() &&
               fs::exists(PathIn(dir, rundir::kGroundTruthMapFile));
  if (*evaluated) {
    for (const auto& [name, filter] : summary["filters"].items()) {
      if (!filter.is_object() || !filter.contains("mean_nees")) *evaluated = false;
    }
  }
  return true;
}

bool PlanRun(bool evaluate_runs, PlannedRun* run) {
  bool evaluated = false;
  if (IsCompletedRun(run->dir, &evaluated)) {
    run->stage = RunStage::kEvaluate;
    return !evaluated && evaluate_runs;
  }
  // A run still alive from an earlier sweep (one killed so hard that its
  // runs outlived it) holds its folder: refuse rather than delete its files
  // and start a second writer beside it.
  if (fs::exists(run->dir)) {
    const rundir::RunDirectoryLock held(run->dir);
    fs::remove_all(run->dir);
  }
  fs::remove(run->dir + ".log");
  run->stage = RunStage::kRun;
  return true;
}

RunPoolResult RunPool(std::deque<PlannedRun> pending, int jobs, const RunPoolOptions& options) {
  RunPoolResult result;
  std::vector<ActiveRun> active;
  while (!pending.empty() || !active.empty()) {
    if (options.stop_requested != nullptr && *options.stop_requested != 0) {
      // Stop the running ones; the next sweep redoes them.
      for (const ActiveRun& a : active) ::kill(a.pid, SIGTERM);
      for (const ActiveRun& a : active) ::waitpid(a.pid, nullptr, 0);
      result.interrupted = true;
      return result;
    }
    while (static_cast<int>(active.size()) < jobs && !pending.empty()) {
      ActiveRun a{pending.front(), -1};
      pending.pop_front();
      a.pid = Start(a.run, options);
      active.push_back(a);
    }
    // Poll, so that a stop is seen at once (a blocking wait is restarted
    // after the signal handler); 1 ms keeps a freed core idle for little.
    int status = 0;
    struct rusage usage {};
    const pid_t pid = ::wait4(-1, &status, WNOHANG, &usage);
    if (pid <= 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    result.child_cpu_s += CpuSeconds(usage);
    for (std::size_t k = 0; k < active.size(); ++k) {
      if (active[k].pid != pid) continue;
      PlannedRun run = active[k].run;
      active.erase(active.begin() + static_cast<std::ptrdiff_t>(k));
      const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
      if (!ok) {
        result.failures.push_back(run.dir + (run.stage == RunStage::kRun ? ": run" : ": evaluate") +
                                  " failed, see " + run.dir + ".log");
        break;
      }
      if (run.stage == RunStage::kRun) ++result.runs_made;
      if (run.stage == RunStage::kRun && options.evaluate_runs) {
        // Evaluate it next, at once, in the slot it frees.
        run.stage = RunStage::kEvaluate;
        active.push_back({run, Start(run, options)});
      } else if (options.verbose) {
        std::fprintf(stderr, "%s: done\n", run.dir.c_str());
      }
      break;
    }
  }
  return result;
}

}  // namespace mjslam::app
