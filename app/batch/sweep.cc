#include "app/batch/sweep.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <limits>
#include <set>
#include <stdexcept>
#include <thread>

#include "app/batch/run_pool.h"
#include "config/config.h"
#include "common/chi_square.h"
#include "common/interrupt.h"
#include "rundir/csv_reader.h"
#include "rundir/csv_writer.h"
#include "rundir/layout.h"
#include "rundir/manifest.h"
#include "rundir/run_files.h"
#include "rundir/summary.h"

namespace mjslam::app {
namespace {

namespace fs = std::filesystem;
using rundir::FormatDouble;
using rundir::PathIn;
using rundir::ReadJsonFile;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The layout of a sweep directory beyond a run's (docs/commands.md).
constexpr char kSweepRecordFile[] = "sweep.json";
constexpr char kCellsFolder[] = "cells";
constexpr char kSlurmFolder[] = "slurm";
constexpr char kCampaignTableFile[] = "campaign.csv";

std::string RunName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "run_%03d", index);
  return name;
}

// Checks the options; returns the number of runs at a time.
int CheckedJobs(const SweepOptions& options) {
  if (options.runs < 1) throw std::runtime_error("sweep: --runs must be >= 1 (got " + std::to_string(options.runs) + ")");
  if (options.jobs < 0) throw std::runtime_error("sweep: --jobs must be >= 0 (got " + std::to_string(options.jobs) + ")");
  const int jobs = options.jobs > 0 ? options.jobs
                                    : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  if (options.out_dir.empty()) throw std::runtime_error("sweep: --out is required");
  if (!fs::is_regular_file(options.program)) {
    throw std::runtime_error("sweep: program not found: '" + options.program + "'");
  }
  return jobs;
}

// Makes the sweep directory and writes its config.yaml; returns its path.
// One config per sweep directory: a resumed sweep must be the same sweep.
std::string PrepareSweepDirectory(const RunConfig& config, const std::string& dir) {
  rundir::MakeRunDirectory(dir);
  rundir::MakeRunDirectory(PathIn(dir, rundir::kSweepRunsFolder));
  const std::string config_path = PathIn(dir, rundir::kConfigFile);
  const std::string config_text = config::ToYaml(config);
  if (fs::exists(config_path) && rundir::ReadTextFile(config_path) != config_text) {
    throw std::runtime_error(config_path +
                             ": this sweep directory was made with another config; use the same "
                             "config and --set options to resume it, or another --out");
  }
  rundir::WriteFileAtomically(config_path, config_text);
  return config_path;
}

// The run directories of a cell.
std::vector<std::string> RunDirs(const std::string& cell_dir, int runs) {
  std::vector<std::string> dirs;
  for (int i = 0; i < runs; ++i) {
    dirs.push_back(PathIn(PathIn(cell_dir, rundir::kSweepRunsFolder), RunName(i)));
  }
  return dirs;
}

// The folder of a cell recorded in sweep.json ("." for a plain sweep).
std::string CellDir(const std::string& out_dir, const nlohmann::json& cell) {
  const std::string relative = cell.at("dir").get<std::string>();
  if (relative == ".") return out_dir;
  // A folder inside the sweep: sweep.json must not send the aggregate's
  // writes elsewhere.
  const fs::path path(relative);
  bool inside = !relative.empty() && path.is_relative();
  for (const fs::path& part : path) inside = inside && part != ".." && part != ".";
  if (!inside) {
    throw std::runtime_error(PathIn(out_dir, kSweepRecordFile) + ": cell dir '" + relative +
                             "': expected a folder inside " + out_dir);
  }
  return PathIn(out_dir, relative);
}

// Throws unless `cells` x `runs` is within the limits of `options`.
void CheckSweepSize(std::size_t cells, long long runs, const SweepOptions& options,
                    const std::string& what) {
  if (cells > static_cast<std::size_t>(options.max_cells)) {
    throw std::runtime_error(what + ": more than " + std::to_string(options.max_cells) +
                             " cells (--max-cells " + std::to_string(options.max_cells) + ")");
  }
  if (runs < 1 || static_cast<double>(cells) * static_cast<double>(runs) > options.max_runs) {
    throw std::runtime_error(what + ": " + std::to_string(cells) + " cells x " +
                             std::to_string(runs) + " runs: expected 1 to " +
                             std::to_string(options.max_runs) + " runs in all (--max-runs " +
                             std::to_string(options.max_runs) + ")");
  }
}

// out_dir/sweep.json: what `--aggregate DIR` needs to finish the sweep
// without its command line (cell folders relative to DIR).
nlohmann::json SweepRecord(const std::vector<SweepCell>& cells, int runs, bool campaign,
                           const SweepOptions& options) {
  nlohmann::json record;
  record["campaign"] = campaign;
  record["runs"] = runs;
  record["backend"] = options.backend == SweepBackend::kSlurm ? "slurm" : "local";
  record["evaluate_runs"] = options.evaluate_runs;
  record["divergence_points"] = options.divergence_points;
  record["cells"] = nlohmann::json::array();
  for (const SweepCell& cell : cells) {
    const std::string relative = fs::relative(cell.dir, options.out_dir).lexically_normal().string();
    record["cells"].push_back({{"name", cell.cell.name},
                               {"dir", relative},
                               {"base_seed", cell.config.run.seed},
                               {"overrides", cell.cell.overrides},
                               {"labels", cell.cell.labels}});
  }
  return record;
}

// Refuses to touch a sweep whose job array is still in the queue: its tasks
// write into the run directories a resume would delete (whatever the backend
// of the resume). Asks squeue only when the sweep has a submission.
void RefuseWhileQueued(const std::string& dir) {
  const std::optional<SlurmSubmission> last = LatestSubmission(PathIn(dir, kSlurmFolder));
  if (last && JobInQueue(last->job_id)) {
    throw std::runtime_error(dir + ": Slurm job " + last->job_id +
                             " of this sweep is still in the queue; wait for it (mjslam sweep "
                             "--aggregate " + dir + ") or cancel it (scancel " + last->job_id + ")");
  }
}

RunPoolOptions PoolOptions(const SweepOptions& options) {
  RunPoolOptions pool;
  pool.program = options.program;
  pool.evaluate_runs = options.evaluate_runs;
  pool.divergence_points = options.divergence_points;
  pool.verbose = options.verbose;
  pool.stop_requested = options.stop_requested;
  return pool;
}

// The runs of `submission` that have no completed (and, when evaluating,
// evaluated) run directory, each with its logs.
std::vector<std::string> UnfinishedRuns(const SlurmSubmission& submission, bool evaluate_runs) {
  std::vector<std::string> unfinished;
  for (std::size_t i = 0; i < submission.runs.size(); ++i) {
    const std::string& dir = submission.runs[i].dir;
    bool evaluated = false;
    if (IsCompletedRun(dir, &evaluated) && (evaluated || !evaluate_runs)) continue;
    unfinished.push_back(dir + ": not completed; Slurm task " +
                         std::to_string(i % static_cast<std::size_t>(submission.tasks)) +
                         " of job " + submission.job_id + ", see " + submission.TaskLog(i) +
                         " and " + dir + ".log");
  }
  return unfinished;
}

// Waits for `submission` (unless options.wait is false: then only says it
// was submitted) and returns its unfinished runs.
std::vector<std::string> AwaitSubmission(const SlurmSubmission& submission,
                                         const SweepOptions& options, SweepResult* result) {
  result->job_id = submission.job_id;
  if (!options.wait) {
    result->submitted = true;
    return {};
  }
  if (options.verbose) {
    std::fprintf(stderr, "%s: waiting for Slurm job %s (%zu runs in %d array tasks)\n",
                 options.out_dir.c_str(), submission.job_id.c_str(), submission.runs.size(),
                 submission.tasks);
  }
  if (!WaitForJob(submission.job_id, options.slurm.poll_s, options.stop_requested)) {
    result->interrupted = true;
    return {};
  }
  return UnfinishedRuns(submission, options.evaluate_runs);
}

// Runs what is left of `runs` with the chosen backend. Returns the failures.
std::vector<std::string> RunWhatIsLeft(std::vector<PlannedRun> runs, int jobs,
                                       const SweepOptions& options, SweepResult* result) {
  std::deque<PlannedRun> pending;
  for (PlannedRun& run : runs) {
    bool evaluated = false;
    if (IsCompletedRun(run.dir, &evaluated)) ++result->runs_kept;
    if (PlanRun(options.evaluate_runs, &run)) pending.push_back(run);
  }
  if (options.backend == SweepBackend::kLocal) {
    const RunPoolResult pool = RunPool(pending, jobs, PoolOptions(options));
    result->runs_made = pool.runs_made;
    result->interrupted = pool.interrupted;
    return pool.failures;
  }
  if (pending.empty()) return {};
  const SlurmSubmission submission =
      SubmitJobArray({pending.begin(), pending.end()}, PoolOptions(options), options.slurm,
                     PathIn(options.out_dir, kSlurmFolder));
  std::vector<std::string> failures = AwaitSubmission(submission, options, result);
  for (const PlannedRun& run : pending) {
    bool evaluated = false;
    if (run.stage == RunStage::kRun && IsCompletedRun(run.dir, &evaluated)) ++result->runs_made;
  }
  return failures;
}

// Throws the list of failed runs, if any.
void ThrowIfFailed(const std::vector<std::string>& failures, int total) {
  if (failures.empty()) return;
  std::string message = "sweep: " + std::to_string(failures.size()) + " of " +
                        std::to_string(total) + " runs failed:";
  for (const std::string& f : failures) message += "\n  " + f;
  throw std::runtime_error(message);
}

// Aggregates every cell of the sweep recorded in `record` (sweep.json) into
// its summary.json; a campaign also gets its table. Fills result's summaries.
void AggregateCells(const nlohmann::json& record, const SweepOptions& options, SweepResult* result) {
  const int runs = record.at("runs").get<int>();
  std::vector<CampaignCell> cells;
  for (const nlohmann::json& c : record.at("cells")) {
    const std::string cell_dir = CellDir(options.out_dir, c);
    const std::vector<std::string> run_dirs = RunDirs(cell_dir, runs);
    nlohmann::json summary = AggregateSweep(run_dirs, cell_dir, options);
    summary["sweep"]["runs_made"] = result->runs_made;
    summary["sweep"]["runs_kept"] = result->runs_kept;
    summary["sweep"]["base_seed"] = c.at("base_seed");
    summary["sweep"]["backend"] = record.at("backend");
    rundir::WriteSummary(cell_dir, summary);
    if (!options.divergence_study_points.empty()) {
      WriteDivergenceStudy(run_dirs.front(), options.divergence_study_points,
                           options.divergence_study_realisations,
                           PathIn(cell_dir, rundir::kDivergenceFile));
    }
    result->cell_summaries.push_back(summary);
    cells.push_back({c.at("name").get<std::string>(),
                     c.at("overrides").get<std::vector<std::string>>(),
                     c.at("labels").get<std::vector<std::pair<std::string, std::string>>>()});
  }
  if (record.at("campaign").get<bool>()) {
    rundir::WriteFileAtomically(PathIn(options.out_dir, kCampaignTableFile),
                                CampaignTableCsv(cells, result->cell_summaries));
    result->table = CampaignTableText(cells, result->cell_summaries);
  } else {
    result->summary = result->cell_summaries.front();
  }
}

// RunSweep and RunCampaign: prepares every cell, runs what is left, and
// aggregates.
SweepResult RunCells(const std::vector<SweepCell>& cells, int runs, bool campaign,
                     SweepOptions options) {
  options.runs = runs;
  const int jobs = CheckedJobs(options);
  CheckSweepSize(cells.size(), runs, options, "sweep " + options.out_dir);
  const std::string& dir = options.out_dir;
  // A resume while the sweep still runs would start its runs beside it.
  const rundir::RunDirectoryLock lock(dir);
  RefuseWhileQueued(dir);

  // Each cell's folder and config; then every run of every cell.
  std::vector<PlannedRun> planned;
  for (const SweepCell& cell : cells) {
    ThrowIfInterrupted("sweep preparation");
    cell.config.ValidateOrThrow();
    const std::string config_path = PrepareSweepDirectory(cell.config, cell.dir);
    const std::vector<std::string> run_dirs = RunDirs(cell.dir, runs);
    for (int i = 0; i < runs; ++i) {
      planned.push_back({fs::absolute(config_path).lexically_normal().string(),
                         cell.config.run.seed + static_cast<std::uint64_t>(i),
                         fs::absolute(run_dirs[i]).lexically_normal().string(), RunStage::kRun});
    }
  }
  const nlohmann::json record = SweepRecord(cells, runs, campaign, options);
  rundir::WriteJsonAtomically(PathIn(dir, kSweepRecordFile), record);

  // Run and evaluate what is missing; then the aggregates.
  SweepResult result;
  const std::vector<std::string> failures = RunWhatIsLeft(planned, jobs, options, &result);
  if (result.interrupted || result.submitted) return result;
  result.runs_failed = static_cast<int>(failures.size());
  ThrowIfFailed(failures, static_cast<int>(planned.size()));
  AggregateCells(record, options, &result);
  if (!campaign && options.backend == SweepBackend::kLocal) {
    result.summary["sweep"]["jobs"] = jobs;
    rundir::WriteSummary(dir, result.summary);
  }
  return result;
}

}  // namespace

SweepResult RunSweep(const RunConfig& config, const SweepOptions& options) {
  SweepCell cell{CampaignCell{}, options.out_dir, config};
  return RunCells({cell}, options.runs, false, options);
}

SweepResult RunCampaign(const CampaignParams& campaign, const std::string& config_path,
                        const std::vector<std::string>& overrides, const SweepOptions& options) {
  ThrowIfProblems(campaign.Validate());
  // The grid's size before it is made (a YAML alias repeated on 9 axes is
  // 10^9 cells).
  const int runs = campaign.runs > 0 ? campaign.runs : options.runs;
  CheckSweepSize(CampaignCellCount(campaign, static_cast<std::size_t>(options.max_cells)), runs,
                 options, "campaign");
  std::vector<SweepCell> cells;
  for (const CampaignCell& cell : CampaignCells(campaign)) {
    ThrowIfInterrupted("campaign preparation");
    std::vector<std::string> cell_overrides = overrides;
    cell_overrides.insert(cell_overrides.end(), cell.overrides.begin(), cell.overrides.end());
    RunConfig config;
    try {
      config = LoadRunConfig(config_path, cell_overrides);
    } catch (const std::runtime_error& error) {
      throw std::runtime_error("campaign cell " + cell.name + ":\n" + error.what());
    }
    cells.push_back({cell, PathIn(PathIn(options.out_dir, kCellsFolder), cell.name), config});
  }
  return RunCells(cells, runs, true, options);
}

SweepResult AggregateSweepDirectory(const std::string& dir, const SweepOptions& options) {
  const nlohmann::json record = ReadJsonFile(PathIn(dir, kSweepRecordFile), nullptr);
  if (!record.is_object() || !record.contains("cells") || !record.contains("runs")) {
    throw std::runtime_error(PathIn(dir, kSweepRecordFile) +
                             ": missing or not a sweep record; is " + dir + " a sweep directory?");
  }
  const rundir::RunDirectoryLock lock(dir);
  SweepOptions with_dir = options;
  with_dir.out_dir = dir;
  with_dir.evaluate_runs = record.value("evaluate_runs", true);
  if (!record.at("runs").is_number_integer() || !record.at("cells").is_array()) {
    throw std::runtime_error(PathIn(dir, kSweepRecordFile) + ": runs or cells of the wrong type");
  }
  CheckSweepSize(record.at("cells").size(), record.at("runs").get<long long>(), options,
                 PathIn(dir, kSweepRecordFile));
  for (const nlohmann::json& c : record.at("cells")) CellDir(dir, c);
  SweepResult result;
  // The last job array: wait for it, then list what it left unfinished.
  const std::optional<SlurmSubmission> last = LatestSubmission(PathIn(dir, kSlurmFolder));
  if (last) {
    with_dir.wait = true;
    const std::vector<std::string> failures = AwaitSubmission(*last, with_dir, &result);
    if (result.interrupted) return result;
    result.runs_failed = static_cast<int>(failures.size());
    ThrowIfFailed(failures, static_cast<int>(last->runs.size()));
  }
  // Every run of every cell must be there (a local sweep stopped early).
  std::vector<std::string> missing;
  for (const nlohmann::json& c : record.at("cells")) {
    for (const std::string& run_dir :
         RunDirs(CellDir(dir, c), record.at("runs").get<int>())) {
      bool evaluated = false;
      if (!IsCompletedRun(run_dir, &evaluated) || (with_dir.evaluate_runs && !evaluated)) {
        missing.push_back(run_dir + ": not completed; run the sweep's command again to resume");
      }
    }
  }
  result.runs_failed = static_cast<int>(missing.size());
  ThrowIfFailed(missing, record.at("runs").get<int>() * static_cast<int>(record.at("cells").size()));
  AggregateCells(record, with_dir, &result);
  return result;
}

namespace {

// Mean over runs of the numbers at `pointer` in each run's summary (null if
// none has one).
nlohmann::json MeanOf(const std::vector<nlohmann::json>& summaries, const nlohmann::json::json_pointer& pointer) {
  double sum = 0.0;
  int count = 0;
  for (const nlohmann::json& s : summaries) {
    if (!s.contains(pointer)) continue;
    const nlohmann::json& v = s.at(pointer);
    if (!v.is_number()) continue;
    sum += v.get<double>();
    ++count;
  }
  return count > 0 ? nlohmann::json(sum / count) : nlohmann::json(nullptr);
}

// What the aggregate reads of each run: per filter and run the NEES of every
// step and the time totals; per run the times and the summary.
struct SweepRuns {
  // The filters of the runs (each run's trajectory.csv has the same).
  std::vector<std::string> names;
  std::vector<std::vector<std::vector<double>>> nees;
  std::vector<std::vector<double>> times;
  std::vector<std::vector<double>> processing_s;
  std::vector<std::vector<double>> open_loop_s;
  std::vector<std::vector<double>> max_period_s;
  // Per filter, pooled over every step of every run: steps inside 2 sigma
  // for x, y, th, and the number of steps.
  std::vector<std::array<long, 4>> inside_2sigma_pooled;
  std::vector<nlohmann::json> summaries;
};

// The filters of the runs: those of the first run's trajectory.csv (the
// default ones without runs); a run with other filters is an error naming
// both lists.
std::vector<std::string> SweepFilterNames(const std::vector<std::string>& run_dirs) {
  std::vector<std::string> names = rundir::DefaultFilterNames();
  for (std::size_t r = 0; r < run_dirs.size(); ++r) {
    const std::string path = PathIn(run_dirs[r], rundir::kTrajectoryFile);
    const std::vector<std::string> run_names =
        rundir::TrajectoryFilterNames(rundir::ReadCsvHeader(path));
    if (r == 0) {
      names = run_names;
    } else if (run_names != names) {
      auto joined = [](const std::vector<std::string>& list) {
        std::string text;
        for (const std::string& name : list) text += (text.empty() ? "" : ", ") + name;
        return text;
      };
      throw std::runtime_error(path + ": filters " + joined(run_names) + ", not those of " +
                               PathIn(run_dirs[0], rundir::kTrajectoryFile) + " (" +
                               joined(names) + "): a sweep's runs must have the same filters");
    }
  }
  return names;
}

SweepRuns ReadSweepRuns(const std::vector<std::string>& run_dirs) {
  SweepRuns runs;
  runs.names = SweepFilterNames(run_dirs);
  const std::vector<std::string>& names = runs.names;
  runs.nees.resize(names.size());
  runs.processing_s.resize(names.size());
  runs.open_loop_s.resize(names.size());
  runs.max_period_s.resize(names.size());
  runs.inside_2sigma_pooled.assign(names.size(), {0, 0, 0, 0});
  for (const std::string& run_dir : run_dirs) {
    const std::vector<rundir::TrajectoryRow> trajectory =
        rundir::ReadTrajectoryRows(PathIn(run_dir, rundir::kTrajectoryFile));
    std::vector<double> run_times;
    for (const rundir::TrajectoryRow& row : trajectory) run_times.push_back(row.t_s);
    runs.times.push_back(run_times);
    // Only when the trajectory has the truth (not a recording without it).
    const bool has_truth = !trajectory.empty() && !std::isnan(trajectory[0].X_WR_true.x);
    for (std::size_t f = 0; f < names.size(); ++f) {
      runs.nees[f].push_back(PoseNees(trajectory, f));
      for (const eval::PoseStepMetrics& m :
           has_truth ? PoseSteps(trajectory, f) : std::vector<eval::PoseStepMetrics>{}) {
        for (int k = 0; k < 3; ++k) runs.inside_2sigma_pooled[f][k] += m.inside_2sigma[k] ? 1 : 0;
        ++runs.inside_2sigma_pooled[f][3];
      }
      double total_us = 0.0;
      double longest_period_s = 0.0;
      bool has_period = false;  // runs from before the column have none
      for (const rundir::TrajectoryRow& row : trajectory) {
        const rundir::FilterRow& filter = row.filters[f];
        total_us += filter.processing_us;
        if (!std::isnan(filter.period_s)) {
          longest_period_s = std::max(longest_period_s, filter.period_s);
          has_period = true;
        }
      }
      runs.processing_s[f].push_back(total_us * 1e-6);
      if (has_period) runs.max_period_s[f].push_back(longest_period_s);
      // Open loop: the run's accumulated f_open_loop at its last step.
      if (!trajectory.empty() && !std::isnan(trajectory.back().filters[f].open_loop_s)) {
        runs.open_loop_s[f].push_back(trajectory.back().filters[f].open_loop_s);
      }
    }
    runs.summaries.push_back(ReadJsonFile(PathIn(run_dir, rundir::kSummaryFile), nlohmann::json::object()));
  }
  return runs;
}

// Per filter: the steps whose average NEES lies inside, above and below the
// bounds, and the sum of the average NEES over the steps used.
struct NeesCounts {
  std::vector<int> inside;
  std::vector<int> above;
  std::vector<int> below;
  std::vector<double> anees_sum;
  int used_steps = 0;
};

// Per step: average NEES over the runs that reach it, when every such run
// has both filters' NEES (the known start has none), against the bounds for
// that many runs; written to out_dir/nees.csv.
NeesCounts WriteAverageNees(const SweepRuns& runs, const std::string& out_dir,
                            const SweepOptions& options) {
  const std::size_t num_filters = runs.names.size();
  std::size_t num_steps = 0;
  for (const std::vector<double>& run_times : runs.times) num_steps = std::max(num_steps, run_times.size());
  std::string csv = rundir::HeaderLine(rundir::NeesColumns(runs.names));
  NeesCounts counts{std::vector<int>(num_filters, 0), std::vector<int>(num_filters, 0),
                    std::vector<int>(num_filters, 0), std::vector<double>(num_filters, 0.0), 0};
  for (std::size_t k = 0; k < num_steps; ++k) {
    int n = 0;
    double t = kNaN;
    bool defined = true;
    std::vector<double> sum(num_filters, 0.0);
    for (std::size_t r = 0; r < runs.times.size(); ++r) {
      if (k >= runs.times[r].size()) continue;
      if (n == 0) t = runs.times[r][k];
      ++n;
      for (std::size_t f = 0; f < num_filters; ++f) {
        const double v = runs.nees[f][r][k];
        if (!std::isfinite(v)) defined = false;
        sum[f] += v;
      }
    }
    if (n == 0 || !defined) continue;
    ++counts.used_steps;
    const Interval bounds = AverageNeesBounds(n, 3, options.bounds_probability);
    csv += FormatDouble(t);
    for (std::size_t f = 0; f < num_filters; ++f) {
      const double anees = sum[f] / n;
      counts.anees_sum[f] += anees;
      if (anees < bounds.lower) ++counts.below[f];
      else if (anees > bounds.upper) ++counts.above[f];
      else ++counts.inside[f];
      csv += "," + FormatDouble(anees);
    }
    csv += "," + FormatDouble(bounds.lower) + "," + FormatDouble(bounds.upper) + "," +
           std::to_string(n) + "\n";
  }
  rundir::WriteFileAtomically(PathIn(out_dir, rundir::kNeesFile), csv);
  return counts;
}

// The aggregate of filter `f`: fractions, verdict, times, and the mean of the
// runs' own metrics.
nlohmann::json FilterAggregate(std::size_t f, const SweepRuns& runs, const NeesCounts& counts,
                               const SweepOptions& options) {
  const std::string& name = runs.names[f];
  const std::size_t num_runs = runs.times.size();
  const int used_steps = counts.used_steps;
  auto mean = [](const std::vector<double>& v) {
    if (v.empty()) return nlohmann::json(nullptr);
    double s = 0.0;
    for (const double x : v) s += x;
    return nlohmann::json(s / v.size());
  };
  nlohmann::json j;
  const double steps = std::max(used_steps, 1);
  j["fraction_inside"] = counts.inside[f] / steps;
  j["fraction_above"] = counts.above[f] / steps;
  j["fraction_below"] = counts.below[f] / steps;
  j["mean_anees"] = used_steps > 0 ? nlohmann::json(counts.anees_sum[f] / used_steps) : nlohmann::json(nullptr);
  std::string verdict = "consistent";
  if (used_steps == 0) verdict = "undetermined";
  else if (counts.inside[f] / steps < options.min_fraction_inside) {
    verdict = counts.above[f] >= counts.below[f] ? "overconfident" : "underconfident";
  }
  j["verdict"] = verdict;
  // The processing time behind the command period (the runs' summaries:
  // the cost model or the scaled measurement), and the measured f_us sum.
  const nlohmann::json model = MeanOf(
      runs.summaries, nlohmann::json::json_pointer("/filters/" + name + "/processing_s"));
  j["processing_s"] = model;
  j["measured_processing_s"] = mean(runs.processing_s[f]);
  // Only when every run has the period column.
  const std::vector<double>& max_period_s = runs.max_period_s[f];
  j["open_loop_s"] = runs.open_loop_s[f].size() == num_runs ? mean(runs.open_loop_s[f]) : nullptr;
  j["max_period_s"] = max_period_s.size() == num_runs && num_runs > 0
                          ? nlohmann::json(*std::max_element(max_period_s.begin(), max_period_s.end()))
                          : nlohmann::json(nullptr);
  // Inside 2 sigma per component over the steps of all runs pooled.
  const std::array<long, 4>& pooled = runs.inside_2sigma_pooled[f];
  const double pooled_steps = static_cast<double>(pooled[3]);
  j["inside_2sigma_pooled"] =
      pooled[3] == 0 ? nlohmann::json(nullptr)
                     : nlohmann::json{{"x", pooled[0] / pooled_steps},
                                      {"y", pooled[1] / pooled_steps},
                                      {"th", pooled[2] / pooled_steps},
                                      {"steps", pooled[3]}};
  // The mean over runs of each run's own metrics (mjslam evaluate).
  const std::string base = "/filters/" + name;
  for (const char* key : {"mean_nees"}) {
    j["runs_mean"][key] = MeanOf(runs.summaries, nlohmann::json::json_pointer(base + "/" + key));
  }
  for (const char* group : {"inside_2sigma", "rmse", "final_pose_error"}) {
    for (const char* c : {"x", "y", "th"}) {
      j["runs_mean"][group][c] =
          MeanOf(runs.summaries, nlohmann::json::json_pointer(base + "/" + group + "/" + c));
    }
  }
  for (const char* key : {"num_estimates", "num_truth", "matched_estimates", "matched_truth",
                          "matched_fraction", "seen_truth", "matched_seen_fraction",
                          "duplicates", "unmatched_estimates",
                          "inconsistent", "mean_feature_nees", "line_rho_rmse_m",
                          "line_alpha_rmse_rad", "corner_rmse_m"}) {
    j["runs_mean"]["map"][key] =
        MeanOf(runs.summaries, nlohmann::json::json_pointer(base + "/map/" + key));
  }
  return j;
}

}  // namespace

nlohmann::json AggregateSweep(const std::vector<std::string>& run_dirs, const std::string& out_dir,
                              const SweepOptions& options) {
  const SweepRuns runs = ReadSweepRuns(run_dirs);
  const NeesCounts counts = WriteAverageNees(runs, out_dir, options);
  nlohmann::json summary;
  summary["sweep"] = {{"completed_runs", static_cast<int>(run_dirs.size())},
                      {"steps", counts.used_steps},
                      {"bounds", {{"probability", options.bounds_probability}, {"dof", 3}}},
                      {"min_fraction_inside", options.min_fraction_inside}};
  for (std::size_t f = 0; f < runs.names.size(); ++f) {
    summary["filters"][runs.names[f]] = FilterAggregate(f, runs, counts, options);
  }
  // The mean of the runs' divergences, when they were evaluated with one:
  // each of their pairs' labels (eval::DivergenceLabels), by name.
  std::set<std::string> labels;
  for (const nlohmann::json& s : runs.summaries) {
    if (!s.contains("divergence") || !s["divergence"].is_object()) continue;
    for (const auto& [key, value] : s["divergence"].items()) {
      if (key != "num_points" && key != "realisations") labels.insert(key);
    }
  }
  for (const std::string& label : labels) {
    const nlohmann::json value =
        MeanOf(runs.summaries, nlohmann::json::json_pointer("/divergence/" + label));
    if (!value.is_null()) summary["divergence"]["runs_mean"][label] = value;
  }
  return summary;
}

}  // namespace mjslam::app
