#pragma once

#include <csignal>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/batch/campaign.h"
#include "app/jobs/evaluate.h"
#include "app/engine/run_config.h"
#include "app/batch/slurm.h"

namespace mjslam::app {

/// Where the runs of a sweep run.
enum class SweepBackend {
  kLocal,  ///< processes on this machine, `jobs` at a time
  kSlurm,  ///< one Slurm job array (app/batch/slurm.h)
};

/// How `mjslam sweep` runs its Monte Carlo.
struct SweepOptions {
  /// Number of runs; run i has seed run.seed + i and lives in
  /// out_dir/runs/run_<i, 3 digits>.
  int runs = 1;
  /// The most cells a campaign may have, and the most runs a sweep or
  /// campaign may have in all (cells x runs): checked before any cell or run
  /// is prepared (--max-cells, --max-runs).
  int max_cells = 1000;
  int max_runs = 100000;
  /// Runs at a time (separate processes); 0: one per core
  /// (std::thread::hardware_concurrency()).
  int jobs = 0;
  /// The sweep directory.
  std::string out_dir;
  /// The mjslam program that runs (`run`) and evaluates (`evaluate`) each run.
  std::string program;
  /// Evaluate each run (`mjslam evaluate`); without it the aggregate has the
  /// NEES and times but no per-run metrics (runs_mean).
  bool evaluate_runs = true;
  /// Divergence of each run's evaluation (`evaluate --divergence-points`);
  /// 0: none.
  int divergence_points = 0;
  /// After the sweep, also write out_dir/divergence.csv from the first run
  /// (`mjslam divergence` with these numbers of points and realisations;
  /// empty: not).
  std::vector<int> divergence_study_points;
  int divergence_study_realisations = 100;
  /// A verdict is "consistent" when at least this fraction of the steps have
  /// the average NEES inside the bounds.
  double min_fraction_inside = 0.9;
  /// Probability of the two-sided average-NEES bounds.
  double bounds_probability = 0.95;
  /// Print one line per finished run to stderr.
  bool verbose = true;
  /// Local processes or a Slurm job array.
  SweepBackend backend = SweepBackend::kLocal;
  /// The job array's settings (kSlurm).
  SlurmOptions slurm;
  /// kSlurm: wait for the array to leave the queue, then aggregate; false:
  /// return once submitted (`mjslam sweep --aggregate DIR` finishes).
  bool wait = true;
  /// Set asynchronously (signal handler) to stop: running runs are stopped
  /// (and redone by the next sweep), nothing is aggregated.
  const volatile std::sig_atomic_t* stop_requested = nullptr;
};

/// One cell of a sweep: `runs` runs of one config in its own sweep
/// directory (config.yaml, runs/, nees.csv, summary.json).
struct SweepCell {
  /// The grid cell (name, overrides, labels); empty for a plain sweep.
  CampaignCell cell;
  /// Its sweep directory: the sweep's own for a plain sweep, else
  /// out_dir/cells/<name>.
  std::string dir;
  RunConfig config;
};

/// What a sweep did.
struct SweepResult {
  /// Runs made now, runs kept from an earlier sweep, runs that failed.
  int runs_made = 0;
  int runs_kept = 0;
  int runs_failed = 0;
  bool interrupted = false;
  /// kSlurm without waiting: the job array was submitted (or nothing was
  /// left to run); no aggregate yet.
  bool submitted = false;
  /// The submitted job's id (kSlurm; empty when nothing was left to run).
  std::string job_id;
  /// The aggregate written to out_dir/summary.json (a plain sweep).
  nlohmann::json summary;
  /// Per cell, in order: its aggregate (a campaign; the plain sweep's one).
  std::vector<nlohmann::json> cell_summaries;
  /// The table across cells (a campaign): as printed.
  std::string table;
};

/// Runs a Monte Carlo sweep: `config` (already loaded, with its overrides) is
/// written to out_dir/config.yaml, and run i is `program run --config
/// out_dir/config.yaml --seed <run.seed + i> --out out_dir/runs/<name>`
/// followed by `program evaluate`, `jobs` runs at a time (kLocal) or in one
/// Slurm job array (kSlurm). So each run's files are those of a single
/// `mjslam run` with that seed, whatever the backend. Resumable: a run whose
/// manifest says completed is kept (and only evaluated if its summary lacks
/// the metrics); any other is deleted and redone. A sweep directory made with
/// another config is refused (std::runtime_error naming its config.yaml), and
/// so is one whose Slurm job is still in the queue. Then aggregates
/// (AggregateSweep). Throws std::runtime_error when runs or evaluations fail,
/// after the others have finished, listing each with its log (and its Slurm
/// task's log).
SweepResult RunSweep(const RunConfig& config, const SweepOptions& options);

/// A campaign: RunSweep over every cell of `campaign` (each cell's config is
/// `config_path` with `overrides`, then the cell's own overrides), all cells'
/// runs in one pool or one job array, each cell in out_dir/cells/<name>/;
/// then every cell's aggregate, and the table across cells written to
/// out_dir/campaign.csv (CampaignTableCsv) and returned as text. Runs per
/// cell: campaign.runs, else options.runs. Throws as RunSweep, and
/// config::ConfigError when a cell's config is bad (naming the cell).
SweepResult RunCampaign(const CampaignParams& campaign, const std::string& config_path,
                        const std::vector<std::string>& overrides, const SweepOptions& options);

/// `mjslam sweep --aggregate DIR`: finishes a sweep or campaign started with
/// `--no-wait`: waits while its Slurm job is in the queue, then aggregates as
/// RunSweep or RunCampaign would (from DIR/sweep.json). Throws
/// std::runtime_error listing the runs without a completed, evaluated run
/// directory, each with its Slurm task's log.
SweepResult AggregateSweepDirectory(const std::string& dir, const SweepOptions& options);

/// The aggregate of the completed runs `run_dirs` of a sweep: writes
/// out_dir/nees.csv (t,classical_anees,selective_anees,lower,upper,n_runs:
/// per step, the average pose NEES over the runs that have it and the
/// two-sided bounds for n_runs) and returns the summary (docs/commands.md, "mjslam
/// sweep"): per filter the fraction of steps inside, above and below the
/// bounds, the mean ANEES, the verdict, accumulated processing time and
/// (with f_period columns) open-loop time, and the mean of the runs' metrics.
nlohmann::json AggregateSweep(const std::vector<std::string>& run_dirs, const std::string& out_dir,
                              const SweepOptions& options);

}  // namespace mjslam::app
