#pragma once

// The Slurm backend of `mjslam sweep`: the runs left are written to a plan,
// one job array is submitted with `sbatch --array`, each array task runs its
// share of the plan (`mjslam sweep-task PLAN TASK`) into the sweep directory
// on the shared filesystem, and the sweep waits for the array to leave the
// queue (`squeue`). No scheduler of our own: Slurm decides where and when.
// docs/cluster.md is the user's guide.

#include <csignal>
#include <optional>
#include <string>
#include <vector>

#include "app/batch/run_pool.h"

namespace mjslam::app {

/// The `sbatch` settings of the job array (docs/commands.md, "Slurm backend").
struct SlurmOptions {
  /// Array tasks running at once (`--array=0-K%N`); 0: no limit.
  int max_running = 0;
  /// `--partition`, `--time`, `--mem`; empty: the cluster's default.
  std::string partition;
  std::string time_limit;
  std::string memory;
  /// Further sbatch options, each written as one `#SBATCH` line (e.g.
  /// "--account=lab", "--qos=long").
  std::vector<std::string> extra_options;
  /// Runs per array task; more when the array would exceed kMaxArrayTasks.
  int runs_per_task = 1;
  /// Seconds between two looks at the queue while waiting.
  double poll_s = 10.0;
};

/// Slurm's default MaxArraySize is 1001 (indices 0..1000): at most this many
/// tasks per array.
inline constexpr int kMaxArrayTasks = 1000;

/// One submitted job array: its folder `<sweep>/slurm/submit_<n>/` holds
/// job.sh, plan.json, job_id and the tasks' logs task_<a>.log.
struct SlurmSubmission {
  std::string folder;
  std::string job_id;
  /// The runs of the plan; run i is done by task i % tasks.
  std::vector<PlannedRun> runs;
  int tasks = 0;

  /// The Slurm log of the task that had run `index` of `runs`.
  std::string TaskLog(std::size_t index) const;
};

/// Writes the plan and the job script of `runs` under `slurm_dir` (a new
/// submit_<n> folder) and submits it (`sbatch --parsable`). `pool` gives the
/// program and the evaluation; the program and every path must be on a
/// filesystem the nodes share. Throws std::runtime_error with sbatch's own
/// message when it refuses, or when sbatch is not found.
SlurmSubmission SubmitJobArray(const std::vector<PlannedRun>& runs, const RunPoolOptions& pool,
                               const SlurmOptions& options, const std::string& slurm_dir);

/// The last submission under `slurm_dir`, if any (read back from its folder).
std::optional<SlurmSubmission> LatestSubmission(const std::string& slurm_dir);

/// True while any task of job `job_id` is pending, running or completing
/// (`squeue -h -j`). A job Slurm no longer knows is not in the queue. Throws
/// std::runtime_error when squeue fails otherwise (no controller).
bool JobInQueue(const std::string& job_id);

/// Waits until job `job_id` leaves the queue, looking every `poll_s`
/// seconds. Returns false when `*stop_requested` was set meanwhile (the job
/// goes on).
bool WaitForJob(const std::string& job_id, double poll_s,
                const volatile std::sig_atomic_t* stop_requested);

/// What one array task does (`mjslam sweep-task PLAN TASK`): the runs i of
/// the plan with i % tasks == task, one at a time, each planned again first
/// (a completed run is kept, a partial one redone: a requeued task resumes).
/// Returns the pool's result.
RunPoolResult RunSweepTask(const std::string& plan_path, int task,
                           const volatile std::sig_atomic_t* stop_requested);

}  // namespace mjslam::app
