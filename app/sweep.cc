#include "app/sweep.h"

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fcntl.h>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <thread>

#include "config/config.h"
#include "eval/chi_square.h"
#include "rundir/csv_reader.h"
#include "rundir/csv_writer.h"
#include "rundir/layout.h"
#include "rundir/manifest.h"
#include "rundir/run_files.h"
#include "rundir/summary.h"

extern char** environ;

namespace mjslam::app {
namespace {

namespace fs = std::filesystem;
using rundir::CsvTable;
using rundir::FilterNames;
using rundir::FormatDouble;
using rundir::PathIn;
using rundir::ReadJsonFile;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string RunName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "run_%03d", index);
  return name;
}

// Starts `argv` with stdout and stderr appended to `log_path`.
pid_t Spawn(const std::vector<std::string>& argv, const std::string& log_path) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(),
                                   O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = -1;
  const int error = posix_spawn(&pid, argv[0].c_str(), &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) {
    throw std::runtime_error("cannot start '" + argv[0] + "': " + std::strerror(error));
  }
  return pid;
}

// True when the run directory holds a completed run; `evaluated` tells if its
// summary has the metrics of `mjslam evaluate`.
bool Completed(const std::string& dir, bool* evaluated) {
  nlohmann::json manifest;
  nlohmann::json summary;
  try {
    manifest = ReadJsonFile(PathIn(dir, rundir::kManifestFile), nullptr);
    summary = ReadJsonFile(PathIn(dir, rundir::kSummaryFile), nullptr);
  } catch (const std::runtime_error&) {
    return false;  // a file cut short: redo the run
  }
  if (!manifest.is_object() || manifest.value("status", "") != "completed") return false;
  *evaluated = summary.is_object() && summary.contains("filters") &&
               summary["filters"].contains("selective") &&
               summary["filters"]["selective"].contains("mean_nees") &&
               fs::exists(PathIn(dir, rundir::kGroundTruthMapFile));
  return true;
}

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

// What a run of the sweep needs next.
enum class Stage { kRun, kEvaluate };

// One run of the sweep in the process pool.
struct Job {
  int index;
  std::string dir;
  Stage stage;
  pid_t pid = -1;
};

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

// The work left: a completed run is kept (and evaluated if its summary lacks
// the metrics); any other is deleted and redone.
std::deque<Job> PlanJobs(const std::vector<std::string>& run_dirs, const SweepOptions& options,
                         SweepResult* result) {
  std::deque<Job> pending;
  for (int i = 0; i < static_cast<int>(run_dirs.size()); ++i) {
    const std::string& run_dir = run_dirs[i];
    bool evaluated = false;
    if (Completed(run_dir, &evaluated)) {
      ++result->runs_kept;
      if (!evaluated && options.evaluate_runs) pending.push_back({i, run_dir, Stage::kEvaluate});
      continue;
    }
    // A run still alive from an earlier sweep (one killed so hard that its
    // runs outlived it) holds its folder: refuse rather than delete its files
    // and start a second writer beside it.
    if (fs::exists(run_dir)) {
      const rundir::RunDirectoryLock held(run_dir);
      fs::remove_all(run_dir);
    }
    fs::remove(run_dir + ".log");
    pending.push_back({i, run_dir, Stage::kRun});
  }
  return pending;
}

// Starts the process of `job`'s stage: `mjslam run` or `mjslam evaluate`.
void StartJob(const RunConfig& config, const std::string& config_path, const SweepOptions& options,
              Job* job) {
  const std::uint64_t seed = config.run.seed + static_cast<std::uint64_t>(job->index);
  if (job->stage == Stage::kRun) {
    job->pid = Spawn({options.program, "run", "--quiet", "--no-render", "--no-evaluate",
                      "--config", config_path, "--seed",
                      std::to_string(seed), "--out", job->dir},
                     job->dir + ".log");
  } else {
    job->pid = Spawn({options.program, "evaluate", job->dir, "--divergence-points",
                      std::to_string(options.divergence_points)},
                     job->dir + ".log");
  }
}

// Runs `pending`, `jobs` processes at a time; a run that succeeds is then
// evaluated. Returns the failures; sets result->interrupted (and stops the
// running processes) when a stop is requested.
std::vector<std::string> RunJobs(std::deque<Job> pending, int jobs, const RunConfig& config,
                                 const std::string& config_path, const SweepOptions& options,
                                 SweepResult* result) {
  std::vector<Job> active;
  std::vector<std::string> failures;
  while (!pending.empty() || !active.empty()) {
    if (options.stop_requested != nullptr && *options.stop_requested != 0) {
      // Stop the running ones; the next sweep redoes them.
      for (const Job& job : active) ::kill(job.pid, SIGTERM);
      for (const Job& job : active) ::waitpid(job.pid, nullptr, 0);
      result->interrupted = true;
      return failures;
    }
    while (static_cast<int>(active.size()) < jobs && !pending.empty()) {
      Job job = pending.front();
      pending.pop_front();
      StartJob(config, config_path, options, &job);
      active.push_back(job);
    }
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, WNOHANG);
    if (pid <= 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      continue;
    }
    for (std::size_t k = 0; k < active.size(); ++k) {
      if (active[k].pid != pid) continue;
      Job job = active[k];
      active.erase(active.begin() + static_cast<std::ptrdiff_t>(k));
      const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
      if (!ok) {
        ++result->runs_failed;
        failures.push_back(job.dir + (job.stage == Stage::kRun ? ": run" : ": evaluate") +
                           " failed, see " + job.dir + ".log");
      } else if (job.stage == Stage::kRun && options.evaluate_runs) {
        job.stage = Stage::kEvaluate;
        StartJob(config, config_path, options, &job);
        active.push_back(job);
        ++result->runs_made;
      } else if (job.stage == Stage::kRun) {
        ++result->runs_made;
      } else if (options.verbose) {
        std::fprintf(stderr, "%s: done\n", job.dir.c_str());
      }
      break;
    }
  }
  return failures;
}

}  // namespace

SweepResult RunSweep(const RunConfig& config, const SweepOptions& options) {
  config.ValidateOrThrow();
  const int jobs = CheckedJobs(options);
  const std::string& dir = options.out_dir;
  // A resume while the sweep still runs would start its runs beside it.
  const rundir::RunDirectoryLock lock(dir);
  const std::string config_path = PrepareSweepDirectory(config, dir);
  std::vector<std::string> run_dirs;
  for (int i = 0; i < options.runs; ++i) {
    run_dirs.push_back(PathIn(PathIn(dir, rundir::kSweepRunsFolder), RunName(i)));
  }

  // Run and evaluate what is missing, J processes at a time.
  SweepResult result;
  const std::vector<std::string> failures =
      RunJobs(PlanJobs(run_dirs, options, &result), jobs, config, config_path, options, &result);
  if (result.interrupted) return result;
  if (!failures.empty()) {
    std::string message = "sweep: " + std::to_string(failures.size()) + " of " +
                          std::to_string(options.runs) + " runs failed:";
    for (const std::string& f : failures) message += "\n  " + f;
    throw std::runtime_error(message);
  }

  // The aggregate, and the divergence study of the first run.
  result.summary = AggregateSweep(run_dirs, dir, options);
  result.summary["sweep"]["runs_made"] = result.runs_made;
  result.summary["sweep"]["runs_kept"] = result.runs_kept;
  result.summary["sweep"]["base_seed"] = config.run.seed;
  result.summary["sweep"]["jobs"] = jobs;
  rundir::WriteSummary(dir, result.summary);
  if (!options.divergence_study_points.empty()) {
    WriteDivergenceStudy(run_dirs.front(), options.divergence_study_points,
                         options.divergence_study_realisations, PathIn(dir, rundir::kDivergenceFile));
  }
  return result;
}

namespace {

// What the aggregate reads of each run: per filter and run the NEES of every
// step and the time totals; per run the times and the summary.
struct SweepRuns {
  std::vector<std::vector<std::vector<double>>> nees;
  std::vector<std::vector<double>> times;
  std::vector<std::vector<double>> processing_s;
  std::vector<std::vector<double>> open_loop_s;
  std::vector<std::vector<double>> max_period_s;
  std::vector<nlohmann::json> summaries;
};

SweepRuns ReadSweepRuns(const std::vector<std::string>& run_dirs) {
  const std::vector<std::string>& names = FilterNames();
  SweepRuns runs;
  runs.nees.resize(names.size());
  runs.processing_s.resize(names.size());
  runs.open_loop_s.resize(names.size());
  runs.max_period_s.resize(names.size());
  for (const std::string& run_dir : run_dirs) {
    const CsvTable table = rundir::ReadCsv(PathIn(run_dir, rundir::kTrajectoryFile));
    const int t = table.ColumnIndex("t");
    std::vector<double> run_times;
    for (const std::vector<double>& row : table.rows) run_times.push_back(row[t]);
    runs.times.push_back(run_times);
    for (std::size_t f = 0; f < names.size(); ++f) {
      runs.nees[f].push_back(PoseNees(table, names[f]));
      const int us = table.ColumnIndex(names[f] + "_us");
      double total_us = 0.0;
      for (const std::vector<double>& row : table.rows) total_us += row[us];
      runs.processing_s[f].push_back(total_us * 1e-6);
      // Open loop: the run's accumulated f_open_loop at its last step.
      for (std::size_t c = 0; c < table.columns.size(); ++c) {
        if (table.columns[c] == names[f] + "_open_loop" && !table.rows.empty()) {
          runs.open_loop_s[f].push_back(table.rows.back()[c]);
        }
        if (table.columns[c] != names[f] + "_period") continue;
        double longest = 0.0;
        for (const std::vector<double>& row : table.rows) longest = std::max(longest, row[c]);
        runs.max_period_s[f].push_back(longest);
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
  const std::size_t num_filters = FilterNames().size();
  std::size_t num_steps = 0;
  for (const std::vector<double>& run_times : runs.times) num_steps = std::max(num_steps, run_times.size());
  std::string csv = rundir::HeaderLine(rundir::NeesColumns());
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
    const eval::Interval bounds = eval::AverageNeesBounds(n, 3, options.bounds_probability);
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
  const std::string& name = FilterNames()[f];
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
                          "matched_fraction", "duplicates", "unmatched_estimates",
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
  for (std::size_t f = 0; f < FilterNames().size(); ++f) {
    summary["filters"][FilterNames()[f]] = FilterAggregate(f, runs, counts, options);
  }
  // The mean of the runs' divergences, when they were evaluated with one.
  for (const char* pair : {"classical_selective", "selective_classical", "classical_truth",
                           "selective_truth"}) {
    const nlohmann::json value =
        MeanOf(runs.summaries, nlohmann::json::json_pointer(std::string("/divergence/") + pair));
    if (!value.is_null()) summary["divergence"]["runs_mean"][pair] = value;
  }
  return summary;
}

}  // namespace mjslam::app
