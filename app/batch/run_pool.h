#pragma once

// The runs of a sweep as separate processes: what each run needs next, and a
// pool that runs them J at a time. Used by the local backend of `mjslam sweep`
// (all runs on this machine) and by each task of the Slurm backend (its share
// of the runs, one at a time).

#include <spawn.h>
#include <sys/types.h>

#include <csignal>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace mjslam::app {

/// What a run of a sweep needs next.
enum class RunStage {
  kRun,       ///< `mjslam run` (then `mjslam evaluate` when evaluating)
  kEvaluate,  ///< completed, but its summary.json lacks the metrics
};

/// One run of a sweep: `program run --config config_path --seed seed --out dir`.
struct PlannedRun {
  std::string config_path;
  std::uint64_t seed = 0;
  std::string dir;
  RunStage stage = RunStage::kRun;
};

/// How the runs are run; the same for every run of a sweep.
struct RunPoolOptions {
  /// The mjslam program.
  std::string program;
  /// Evaluate each run after it (`mjslam evaluate`).
  bool evaluate_runs = true;
  /// `evaluate --divergence-points`; 0: none.
  int divergence_points = 0;
  /// Print one line per finished run to stderr.
  bool verbose = true;
  /// Set asynchronously (signal handler) to stop: running runs get SIGTERM
  /// and are waited for.
  const volatile std::sig_atomic_t* stop_requested = nullptr;
};

/// What a pool did.
struct RunPoolResult {
  /// Runs made (`mjslam run` succeeded).
  int runs_made = 0;
  /// One line per failed run: its directory, the stage and its log
  /// (`<dir>.log`).
  std::vector<std::string> failures;
  /// A stop was requested: the running runs were stopped.
  bool interrupted = false;
  /// CPU seconds (user + system) of all the processes the pool waited for.
  double child_cpu_s = 0.0;
};

/// The environment variable through which a sweep tells the `mjslam`
/// processes it starts its process id (StopWithParent).
inline constexpr const char* kStopWithParentVariable = "MJSLAM_STOP_WITH_PARENT";

/// Starts `argv` with `actions` applied in the child (argv[0] is a path, or a
/// name looked up in PATH when `search_path`). With `stop_with_parent`, the
/// child's environment names this process in kStopWithParentVariable (an
/// `mjslam` child then stops when this process dies); an inherited value is
/// never passed on. Throws std::runtime_error naming argv[0] and the reason
/// when it cannot be started.
pid_t StartProcess(const std::vector<std::string>& argv, const posix_spawn_file_actions_t& actions,
                   bool search_path, bool stop_with_parent = false);

/// Called by `main` at start: when the environment names a parent process
/// (kStopWithParentVariable, set by a sweep's pool), asks the kernel to send
/// this process SIGTERM when that parent dies, even by SIGKILL, and calls
/// `stop(SIGTERM)` at once if it has already died. The run then ends as on
/// Ctrl-C: whole rows, manifest `interrupted`, exit 130. The variable is
/// removed, so this process's own children do not inherit it.
void StopWithParent(void (*stop)(int));

/// True when `dir` holds a completed run (manifest status "completed" and a
/// readable summary.json); `*evaluated` tells whether its summary has the
/// metrics of `mjslam evaluate` (and ground_truth_map.csv is there).
bool IsCompletedRun(const std::string& dir, bool* evaluated);

/// The work left for `run`: nothing (a completed run, evaluated or not
/// needed), kEvaluate, or kRun after deleting whatever `run.dir` and its log
/// hold. Returns false when nothing is left.
bool PlanRun(bool evaluate_runs, PlannedRun* run);

/// Runs `pending`, `jobs` processes at a time; a run that succeeds is then
/// evaluated (with options.evaluate_runs). Each process's output is appended
/// to `<dir>.log`. Throws std::runtime_error when the program cannot be
/// started.
RunPoolResult RunPool(std::deque<PlannedRun> pending, int jobs, const RunPoolOptions& options);

}  // namespace mjslam::app
