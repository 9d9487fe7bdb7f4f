// mjslam: the command line. One function adds each subcommand's options and
// one runs it; main() builds the CLI and dispatches. With the tests, the only
// place that catches errors.
#include <malloc.h>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/jobs/calibrate.h"
#include "app/engine/cpu_profile.h"
#include "app/jobs/evaluate.h"
#include "app/jobs/evaluate_real.h"
#include "app/jobs/import_log.h"
#include "app/jobs/render_real.h"
#include "app/jobs/render_run.h"
#include "app/jobs/replay.h"
#include "app/jobs/run.h"
#include "app/engine/run_config.h"
#include "app/batch/run_pool.h"
#include "app/batch/slurm.h"
#include "app/batch/sweep.h"
#include "app/jobs/version.h"
#include "common/interrupt.h"
#include "config/config.h"
#include "rundir/layout.h"
#include "rundir/run_files.h"

namespace mjslam::app {
namespace {

volatile std::sig_atomic_t g_stop_requested = 0;

// The run and render loops poll g_stop_requested; the other long phases
// (evaluation, divergence, world setup, plots) throw Interrupted
// (common/interrupt.h) at their next check.
void RequestStop(int /*signal*/) {
  g_stop_requested = 1;
  RequestInterrupt();
}

std::string JoinArguments(int argc, char** argv) {
  std::string text;
  for (int i = 0; i < argc; ++i) text += (i ? " " : "") + std::string(argv[i]);
  return text;
}

// Checks an unsigned option's text: CLI11 would wrap -1 to 2^64 - 1.
CLI::Validator NonNegativeInteger() {
  return CLI::Validator(
      [](std::string& text) {
        return text.find('-') == std::string::npos
                   ? std::string()
                   : "expected a non-negative integer (got " + text + ")";
      },
      "", "non-negative");
}

// The options every config-loading subcommand shares.
struct ConfigOptions {
  std::string path = std::string(MJSLAM_SOURCE_DIR) + "/configs/default.yaml";
  std::vector<std::string> overrides;
};

void AddConfigOptions(CLI::App* command, ConfigOptions* config, const std::string& set_help) {
  command->add_option("--config", config->path, "YAML config file")->capture_default_str();
  command->add_option("--set", config->overrides, set_help)->type_name("KEY=VALUE");
}

// mjslam run
struct RunCommand {
  ConfigOptions config;
  std::string world;
  std::string out_dir;
  std::uint64_t seed = 0;
  double duration_s = 0.0;
  bool quiet = false;
  bool no_render = false;
  bool no_evaluate = false;
  bool profile = false;
};

CLI::App* AddRun(CLI::App* cli, RunCommand* c) {
  CLI::App* run = cli->add_subcommand("run", "Run one closed-loop simulation and write a run directory");
  AddConfigOptions(run, &c->config,
                   "Override any config key, e.g. --set laser.range_noise_std_m=0 (the simulated "
                   "laser; the filters' model is slam.features.range_noise_std_m)");
  run->add_option("--world", c->world, "World MJCF file (overrides run.world)");
  run->add_option("--seed", c->seed, "Root random seed (overrides run.seed)")
      ->check(NonNegativeInteger());
  run->add_option("--duration", c->duration_s, "Simulated seconds (overrides run.duration_s)");
  run->add_option("--out", c->out_dir, "Run directory [runs/<world>-seed<seed>]");
  run->add_flag("--quiet", c->quiet, "No progress bar");
  run->add_flag("--no-render", c->no_render, "Do not render at the end, whatever render.enabled says");
  run->add_flag("--no-evaluate", c->no_evaluate,
                "Do not evaluate at the end (ground_truth_map.csv, metrics in summary.json)");
  run->add_flag("--profile", c->profile,
                "Print the CPU seconds of each phase of the run (physics, laser, filters, ...) "
                "and simulated seconds per CPU second");
  return run;
}

int RunMain(const CLI::App& run, RunCommand c, const std::string& command_line) {
  // Command-line options are overrides like --set, applied last.
  std::vector<std::string>& overrides = c.config.overrides;
  if (!c.world.empty()) overrides.push_back("run.world=" + c.world);
  if (run.count("--seed") > 0) overrides.push_back("run.seed=" + std::to_string(c.seed));
  if (run.count("--duration") > 0) overrides.push_back("run.duration_s=" + ValueText(c.duration_s));
  const RunConfig config = LoadRunConfig(c.config.path, overrides);
  RunOptions options;
  options.out_dir = c.out_dir;
  if (options.out_dir.empty()) {
    const std::string stem = std::filesystem::path(config.run.world).stem().string();
    options.out_dir = "runs/" + stem + "-seed" + std::to_string(config.run.seed);
  }
  options.config_path = c.config.path;
  options.command_line = command_line;
  options.show_progress = !c.quiet;
  options.stop_requested = &g_stop_requested;
  // The video is rendered as the run goes; the final image, the plots and
  // the page come after the evaluation, from the run's files.
  const bool render = config.render.enabled && !c.no_render;
  options.render_video = render && config.render.video;
  if (const std::optional<std::string> note = RangeNoiseNote(config)) {
    std::fprintf(stderr, "%s\n", note->c_str());
  }
  const RunResult result = RunSimulation(config, options);
  std::fprintf(stderr, "%s: %s after %d steps (%.1f s simulated)\n", options.out_dir.c_str(),
               result.status.c_str(), result.steps, result.sim_time_s);
  for (const std::string& warning : result.warnings) {
    std::fprintf(stderr, "%s: %s\n", options.out_dir.c_str(), warning.c_str());
  }
  if (c.profile && result.sim_time_s > 0.0) {
    std::printf("%s", PhaseCpuReport(result.cpu, result.sim_time_s, ProcessCpuSeconds()).c_str());
  }
  if (result.status != "completed") return 130;
  if (!c.no_evaluate) {
    const RunEvaluation evaluation = EvaluateRunDirectory(options.out_dir, EvaluateOptions{});
    if (!evaluation.no_divergence.empty()) {
      std::fprintf(stderr, "note: no divergence in summary.json: %s\n",
                   evaluation.no_divergence.c_str());
    }
  }
  if (render) {
    RenderOptions render_options;
    render_options.show_progress = !c.quiet;
    render_options.stop_requested = &g_stop_requested;
    renders::RenderParams after_run = config.render;
    after_run.video = false;  // already written during the run
    RenderRun(options.out_dir, after_run, render_options);
    std::fprintf(stderr, "%s: rendered (%d video frames during the run, %.0f frames/s)\n",
                 options.out_dir.c_str(), result.video_frames, result.video_fps);
  }
  return 0;
}

// mjslam replay
struct ReplayCommand {
  ConfigOptions config;
  ReplayOptions options;
};

CLI::App* AddReplay(CLI::App* cli, ReplayCommand* c) {
  CLI::App* replay =
      cli->add_subcommand("replay", "Run both filters on the scans and trajectory of an earlier run");
  replay->add_option("--scans", c->options.scans_path, "scans.csv of an earlier run")->required();
  replay->add_option("--trajectory", c->options.trajectory_path,
                     "Its trajectory.csv [the one beside --scans]");
  replay->add_option("--out", c->options.out_dir, "Output directory")->required();
  AddConfigOptions(replay, &c->config, "Override any config key");
  return replay;
}

int ReplayMain(ReplayCommand c, const std::string& command_line) {
  const RunConfig config = LoadRunConfig(c.config.path, c.config.overrides);
  c.options.config_path = c.config.path;
  c.options.command_line = command_line;
  if (!Replay(config, c.options)) {
    std::fprintf(stderr, "%s: replay interrupted (whole rows written; manifest says interrupted)\n",
                 c.options.out_dir.c_str());
    return 130;
  }
  std::fprintf(stderr, "%s: replay completed\n", c.options.out_dir.c_str());
  return 0;
}

// mjslam import
struct ImportCommand {
  ConfigOptions config;
  ImportOptions options;
  std::string time_offset = "auto";
};

CLI::App* AddImport(CLI::App* cli, ImportCommand* c) {
  c->config.path = std::string(MJSLAM_SOURCE_DIR) + "/configs/real.yaml";
  CLI::App* import = cli->add_subcommand(
      "import", "Import a CARMEN laser log (plain or gzip) or a BreezySLAM log into a run directory and run both filters on it");
  import->add_option("LOG", c->options.log_path, "CARMEN log")->required();
  import->add_option("--out", c->options.out_dir, "Output run directory")->required();
  import->add_option("--format", c->options.format,
                     "Log format: auto, carmen, breezyslam (docs/real_data.md)")->capture_default_str();
  import->add_option("--laser", c->options.laser,
                     "Laser messages to use (FLASER, RLASER, ROBOTLASER1, RAWLASER1, ...) [first found]");
  import->add_option("--angle-min-deg", c->options.read.angle_min_deg,
                     "FLASER/RLASER: bearing of beam 0, degrees")->capture_default_str();
  import->add_option("--angle-step-deg", c->options.read.angle_step_deg,
                     "FLASER/RLASER: step between beams, degrees (0: from the beam count)")
      ->capture_default_str();
  import->add_option("--max-range", c->options.read.max_range_m,
                     "Maximum range, metres (0: from the log, else 81.83)")->capture_default_str();
  import->add_option("--laser-offset", c->options.laser_offset_m,
                     "Laser ahead of the robot centre, metres [PARAM robot_frontlaser_offset, or 0]");
  import->add_option("--reference", c->options.reference,
                     "The laser poses as reference trajectory: auto, yes, no")->capture_default_str();
  import->add_flag("--skip-bad-lines", c->options.read.skip_bad_lines,
                   "Count and report malformed lines instead of stopping at the first");
  import->add_flag("--odometry-as-logged", c->options.read.odometry_as_logged,
                   "Keep ODOM poses as logged where the log restarts them at each scan's corrected "
                   "pose (the corrected logs), instead of rebuilding the wheel odometry");
  import->add_option("--relations", c->options.relations_path, "Relations file (Kuemmerle et al. 2009)");
  import->add_option("--time-offset", c->time_offset,
                     "Relation time minus log time, seconds, or auto (searched)")->capture_default_str();
  import->add_option("--tolerance", c->options.tolerance_s,
                     "Relation time matching tolerance, seconds, in (0, 10]")->capture_default_str();
  import->add_option("--max-offset-candidates", c->options.max_offset_candidates,
                     "Most relation times x scans the time offset search may compare (8 bytes "
                     "each)")
      ->capture_default_str()
      ->check(NonNegativeInteger());
  AddConfigOptions(import, &c->config, "Override any config key");
  return import;
}

int ImportMain(const CLI::App& import, ImportCommand c, const std::string& command_line) {
  // NaN means "from the log" inside; given on the command line it is refused.
  if (import.count("--laser-offset") > 0 && !std::isfinite(c.options.laser_offset_m)) {
    throw std::runtime_error("--laser-offset: expected metres in [-100, 100] (got " +
                             ValueText(c.options.laser_offset_m) + ")");
  }
  const RunConfig config = LoadRunConfig(c.config.path, c.config.overrides);
  c.options.config_path = c.config.path;
  c.options.command_line = command_line;
  if (c.time_offset != "auto") {
    char* end = nullptr;
    c.options.time_offset_s = std::strtod(c.time_offset.c_str(), &end);
    if (end == c.time_offset.c_str() || *end != '\0' || !std::isfinite(c.options.time_offset_s)) {
      throw std::runtime_error("--time-offset: expected a finite number of seconds or auto (got '" +
                               c.time_offset + "')");
    }
  }
  const ImportReport report = ImportLog(config, c.options);
  if (report.interrupted) {
    std::fprintf(stderr, "%s: import interrupted in its replay (whole rows written; manifest says "
                 "interrupted)\n", c.options.out_dir.c_str());
    return 130;
  }
  std::fprintf(stderr, "%s: imported %s: %d %s scans of %d beams, %d odometry messages, %d steps, %s\n",
               c.options.out_dir.c_str(), c.options.log_path.c_str(), report.num_scans,
               report.laser.c_str(), report.num_beams, report.num_odometry, report.num_steps,
               report.has_reference ? "reference trajectory (the log's own estimate)" : "no reference");
  if (report.odometry_rebuilt) {
    std::fprintf(stderr, "  odometry rebuilt from the logged increments (the log restarts it at each scan)\n");
  }
  for (const std::string& line : report.skipped) std::fprintf(stderr, "  skipped %s\n", line.c_str());
  for (const std::string& line : report.warnings) std::fprintf(stderr, "  warning: %s\n", line.c_str());
  if (!c.options.relations_path.empty()) {
    std::fprintf(stderr, "  relations time offset %.6f s\n", report.time_offset_s);
  }
  return 0;
}

// mjslam config
CLI::App* AddConfig(CLI::App* cli, ConfigOptions* c) {
  CLI::App* show =
      cli->add_subcommand("config", "Print the resolved config (defaults, file, overrides) as YAML");
  AddConfigOptions(show, c, "Override any config key");
  return show;
}

int ConfigMain(const ConfigOptions& c) {
  std::fputs(config::ToYaml(LoadRunConfig(c.path, c.overrides)).c_str(), stdout);
  return 0;
}

// mjslam calibrate
struct CalibrateCommand {
  std::vector<std::string> run_dirs;
  ConfigOptions config;
  int window_records = 10;
  std::string write;
};

CLI::App* AddCalibrate(CLI::App* cli, CalibrateCommand* c) {
  CLI::App* calibrate = cli->add_subcommand(
      "calibrate", "Fit the filters' odometry noise to simulated runs (their true and odometry poses)");
  calibrate->add_option("RUN_DIR", c->run_dirs, "Run directories, or sweep directories (their runs)")
      ->required();
  AddConfigOptions(calibrate, &c->config, "Override any config key of the model compared");
  calibrate->add_option("--window-records", c->window_records,
                        "Records summed per window of the variance fit")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  calibrate->add_option("--write", c->write,
                        "Write the fitted keys to this YAML file, with the --config file as its base");
  return calibrate;
}

int CalibrateMain(const CalibrateCommand& c, const std::string& command_line) {
  const RunConfig model = LoadRunConfig(c.config.path, c.config.overrides);
  std::vector<RunMotion> runs;
  for (const std::string& dir : RunDirectories(c.run_dirs)) runs.push_back(ReadRunMotion(dir));
  const Calibration calibration = Calibrate(runs, model.slam.ekf, c.window_records);
  std::fputs(CalibrationReport(calibration, model.slam.ekf).c_str(), stdout);
  if (!c.write.empty()) {
    namespace fs = std::filesystem;
    const fs::path folder = fs::absolute(fs::path(c.write)).parent_path();
    const std::string base = fs::relative(fs::absolute(c.config.path), folder).string();
    const std::string header = "Fitted by mjslam calibrate (" + MjslamGitCommit() + ", " +
                               rundir::UtcNow() + ") to " + std::to_string(runs.size()) +
                               " runs:\n  " + command_line;
    rundir::WriteFileAtomically(c.write, CalibrationYaml(calibration, base, header));
    std::printf("\nwrote %s\n", c.write.c_str());
  }
  return 0;
}

// mjslam evaluate
struct EvaluateCommand {
  std::string run_dir;
  EvaluateOptions options;
  bool profile = false;
};

CLI::App* AddEvaluate(CLI::App* cli, EvaluateCommand* c) {
  CLI::App* evaluate = cli->add_subcommand(
      "evaluate", "Ground truth, pose and map metrics of a run directory, into summary.json");
  evaluate->add_option("RUN_DIR", c->run_dir, "Run directory")->required();
  evaluate->add_option("--divergence-points", c->options.divergence_points,
                       "Monte Carlo points of the map divergence (0: none)")
      ->capture_default_str();
  evaluate->add_option("--realisations", c->options.divergence_realisations,
                       "Realisations of the divergence (their mean is reported)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  evaluate->add_option("--pair", c->options.divergence_pair,
                       "The two filters the divergence compares [classical selective, else the "
                       "first two with a map]")
      ->expected(2);
  evaluate->add_flag("--profile", c->profile, "Print the CPU seconds of each stage");
  return evaluate;
}

// An imported log: the relation metric instead of the world's truth.
int EvaluateImportedMain(const std::string& run_dir) {
  const RealEvaluation result = EvaluateImportedRun(run_dir);
  auto print = [](const std::string& title, const std::vector<ScoredTrajectory>& scored) {
    if (scored.empty()) return;
    std::printf("%s\n%-10s %8s %11s %10s %11s %10s\n", title.c_str(), "", "matched", "trans_mean_m",
                "trans_std_m", "rot_mean_deg", "rot_std_deg");
    for (const ScoredTrajectory& s : scored) {
      std::printf("%-10s %8d %11.4f %10.4f %11.3f %10.3f\n", s.name.c_str(), s.errors.num_matched,
                  s.errors.translation_mean_m, s.errors.translation_std_m,
                  s.errors.rotation_mean_deg, s.errors.rotation_std_deg);
    }
  };
  if (result.relation_times > 0) {
    std::printf("relation timestamps on scans: %d of %d (offset %.6f s, tolerance %.4f s)\n",
                result.relation_times_at_scans, result.relation_times, result.time_offset_s,
                result.tolerance_s);
  }
  print("relations file, poses at scans:", result.at_scans);
  print("relations file, poses at every record:", result.at_records);
  for (std::size_t i = 0; i < result.vs_reference_lags.size(); ++i) {
    const int lag = RealEvaluation::kReferenceLags[i];
    print(lag == 1 ? "reference, consecutive scans:"
                   : "reference, scans " + std::to_string(lag) + " apart:",
          result.vs_reference_lags[i]);
  }
  for (std::size_t f = 0; f < result.num_features.size(); ++f) {
    std::printf("%s: %d features; pose covariance not positive semi-definite in %d rows, "
                "singular in %d\n",
                result.filter_names[f].c_str(), result.num_features[f],
                result.not_positive_semidefinite[f], result.singular[f]);
  }
  return 0;
}

int EvaluateMain(const EvaluateCommand& c) {
  if (IsImportedRun(c.run_dir)) return EvaluateImportedMain(c.run_dir);
  const RunEvaluation result = EvaluateRunDirectory(c.run_dir, c.options);
  std::printf("%-10s %8s %8s %8s %9s %8s %9s %6s %6s\n", "filter", "in2s_x", "in2s_y", "in2s_th",
              "mean_nees", "matched", "dupl", "unm", "incons");
  for (std::size_t i = 0; i < result.pose.size(); ++i) {
    const auto& p = result.pose[i];
    const auto& m = result.map[i];
    std::printf("%-10s %8.3f %8.3f %8.3f %9.3f %8.3f %9d %6d %6d\n",
                result.names[i].c_str(), p.inside_2sigma(0), p.inside_2sigma(1),
                p.inside_2sigma(2), p.mean_nees, m.matched_fraction, m.num_duplicates,
                m.num_unmatched_estimates, m.num_inconsistent);
  }
  const ObservationCheck& o = result.observations;
  std::printf("line observations against the true walls: %d of %d on a wall, mean NIS %.3f "
              "(2 if the extractor's covariances hold), above 9.21: %.4f, largest %.1f, "
              "range bias %.4f m removed\n",
              o.matched, o.lines, o.mean_nis, o.fraction_above_gate, o.max_nis, o.range_bias_m);
  if (!result.no_divergence.empty()) {
    std::printf("no divergence: %s\n", result.no_divergence.c_str());
  }
  if (result.has_divergence) {
    const char* a = result.divergence_pair.first.c_str();
    const char* b = result.divergence_pair.second.c_str();
    std::printf("divergence: %s||%s %.4g, %s||%s %.4g, %s||truth %.4g, %s||truth %.4g\n", a, b,
                result.divergence.first_second, b, a, result.divergence.second_first, a,
                result.divergence.first_truth, b, result.divergence.second_truth);
  }
  if (c.profile) {
    const EvaluationCpu& cpu = result.cpu;
    std::printf("cpu s: trajectory %.3f, ground truth %.3f, observations %.3f, poses %.3f, "
                "maps %.3f, divergence %.3f, summary %.3f, total %.3f\n",
                cpu.trajectory_s, cpu.ground_truth_s, cpu.observations_s, cpu.poses_s, cpu.maps_s,
                cpu.divergence_s, cpu.summary_s, cpu.total_s);
  }
  return 0;
}

// mjslam sweep
struct SweepCommand {
  ConfigOptions config;
  SweepOptions options;
  double duration_s = 0.0;
  bool quiet = false;
  std::string campaign_path;
  std::vector<std::string> worlds;
  std::vector<std::string> vary;
  std::string backend = "local";
  bool no_wait = false;
  std::string aggregate_dir;
};

// The sweep's Slurm options (docs/commands.md, "Slurm backend").
void AddSlurmOptions(CLI::App* sweep, SweepCommand* c) {
  SlurmOptions& slurm = c->options.slurm;
  sweep->add_option("--backend", c->backend, "Where the runs run: local (processes here) or slurm "
                    "(one job array)")
      ->capture_default_str()
      ->check(CLI::IsMember({"local", "slurm"}));
  sweep->add_option("--max-running", slurm.max_running,
                    "slurm: array tasks running at once (--array=...%N; 0: no limit)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  sweep->add_option("--partition", slurm.partition, "slurm: partition (sbatch --partition)");
  sweep->add_option("--time", slurm.time_limit, "slurm: time limit of each array task (sbatch --time)");
  sweep->add_option("--mem", slurm.memory, "slurm: memory of each array task (sbatch --mem, e.g. 2G)");
  sweep->add_option("--sbatch-option", slurm.extra_options,
                    "slurm: any other sbatch option, one per use (e.g. --sbatch-option=--account=lab)");
  sweep->add_option("--runs-per-task", slurm.runs_per_task, "slurm: runs per array task")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  sweep->add_option("--poll", slurm.poll_s, "slurm: seconds between two looks at the queue")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  sweep->add_flag("--no-wait", c->no_wait,
                  "slurm: return once submitted; `mjslam sweep --aggregate DIR` finishes");
}

CLI::App* AddSweep(CLI::App* cli, SweepCommand* c) {
  CLI::App* sweep = cli->add_subcommand(
      "sweep", "Monte Carlo runs with seeds run.seed + i, evaluated and aggregated; a campaign "
               "of such sweeps over worlds and config values; locally or on Slurm");
  AddConfigOptions(sweep, &c->config, "Override any config key");
  sweep->add_option("--runs", c->options.runs, "Number of runs (per cell of a campaign)")
      ->check(CLI::PositiveNumber);
  sweep->add_option("--max-cells", c->options.max_cells, "Most cells a campaign may have")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  sweep->add_option("--max-runs", c->options.max_runs,
                    "Most runs a sweep or campaign may have in all (cells x runs)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  sweep->add_option("--jobs", c->options.jobs, "local: runs at a time (0: one per core)")
      ->capture_default_str()
      ->check(NonNegativeInteger());
  sweep->add_option("--out", c->options.out_dir, "Sweep directory");
  sweep->add_option("--duration", c->duration_s, "Simulated seconds of each run (overrides run.duration_s)");
  sweep->add_option("--divergence-points", c->options.divergence_points,
                    "Map divergence points of each run's evaluation (0: none)")
      ->capture_default_str();
  sweep->add_option("--divergence-study", c->options.divergence_study_points,
                    "Also write DIR/divergence.csv from the first run for these #E (e.g. 100 1000 20000)");
  sweep->add_option("--study-realisations", c->options.divergence_study_realisations,
                    "Realisations per #E of --divergence-study")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  sweep->add_option("--campaign", c->campaign_path,
                    "Campaign file (YAML: runs, worlds, axes): one sweep per cell of the grid");
  sweep->add_option("--world", c->worlds, "A campaign over these worlds (repeat the option)");
  sweep->add_option("--vary", c->vary,
                    "A campaign axis: KEY=V1,V2,... (repeat the option for more axes)");
  sweep->add_option("--aggregate", c->aggregate_dir,
                    "Only finish the sweep in DIR: wait for its Slurm job, then aggregate");
  AddSlurmOptions(sweep, c);
  sweep->add_flag("--quiet", c->quiet, "No line per finished run");
  return sweep;
}

// What a finished sweep prints: a campaign's table, or each filter's verdict.
void PrintSweep(const SweepResult& result) {
  if (!result.table.empty()) {
    std::fputs(result.table.c_str(), stdout);
    return;
  }
  for (const auto& [name, f] : result.summary["filters"].items()) {
    std::printf("%-10s ANEES inside the bounds for %.3f of the steps (above %.3f, below "
                "%.3f), mean ANEES %.3f: %s\n",
                name.c_str(), f["fraction_inside"].get<double>(), f["fraction_above"].get<double>(),
                f["fraction_below"].get<double>(),
                f["mean_anees"].is_number() ? f["mean_anees"].get<double>() : 0.0,
                f["verdict"].get<std::string>().c_str());
  }
}

int SweepMain(const CLI::App& sweep, SweepCommand c) {
  c.options.program = std::filesystem::read_symlink("/proc/self/exe").string();
  c.options.verbose = !c.quiet;
  c.options.stop_requested = &g_stop_requested;
  c.options.backend = c.backend == "slurm" ? SweepBackend::kSlurm : SweepBackend::kLocal;
  c.options.wait = !c.no_wait;
  SweepResult result;
  const bool campaign = !c.campaign_path.empty() || !c.worlds.empty() || !c.vary.empty();
  if (!c.aggregate_dir.empty()) {
    result = AggregateSweepDirectory(c.aggregate_dir, c.options);
    c.options.out_dir = c.aggregate_dir;
  } else {
    if (c.options.out_dir.empty()) throw std::runtime_error("sweep: --out DIR is required");
    if (sweep.count("--duration") > 0) {
      c.config.overrides.push_back("run.duration_s=" + ValueText(c.duration_s));
    }
    if (!c.campaign_path.empty() && (!c.worlds.empty() || !c.vary.empty())) {
      throw std::runtime_error("sweep: --campaign " + c.campaign_path +
                               " and --world/--vary: give the grid one way");
    }
    const CampaignParams grid = !c.campaign_path.empty() ? LoadCampaign(c.campaign_path)
                                                         : CampaignFromOptions(c.worlds, c.vary);
    // --runs is needed unless the campaign file says how many.
    if (sweep.count("--runs") == 0 && !(campaign && grid.runs > 0)) {
      throw std::runtime_error("sweep: --runs N is required (or runs: in the campaign file)");
    }
    CampaignParams with_runs = grid;
    if (sweep.count("--runs") > 0) with_runs.runs = c.options.runs;
    result = campaign ? RunCampaign(with_runs, c.config.path, c.config.overrides, c.options)
                      : RunSweep(LoadRunConfig(c.config.path, c.config.overrides), c.options);
  }
  const std::string& dir = c.options.out_dir;
  if (result.interrupted) {
    std::fprintf(stderr, "%s: interrupted; %s\n", dir.c_str(),
                 result.job_id.empty() ? "run the same command again to resume"
                                       : ("Slurm job " + result.job_id +
                                          " goes on; mjslam sweep --aggregate " + dir +
                                          " finishes the sweep")
                                             .c_str());
    return 130;
  }
  if (result.submitted) {
    std::fprintf(stderr, "%s: submitted Slurm job %s; mjslam sweep --aggregate %s finishes the sweep\n",
                 dir.c_str(), result.job_id.c_str(), dir.c_str());
    return 0;
  }
  PrintSweep(result);
  if (c.aggregate_dir.empty()) {
    std::fprintf(stderr, "%s: %d runs made, %d kept\n", dir.c_str(), result.runs_made,
                 result.runs_kept);
  } else {
    std::fprintf(stderr, "%s: aggregated\n", dir.c_str());
  }
  return 0;
}

// mjslam sweep-task (the job script of the Slurm backend runs it)
struct SweepTaskCommand {
  std::string plan_path;
  int task = 0;
};

CLI::App* AddSweepTask(CLI::App* cli, SweepTaskCommand* c) {
  CLI::App* task = cli->add_subcommand(
      "sweep-task", "One array task of a Slurm sweep: its share of the runs of a plan.json");
  task->add_option("PLAN", c->plan_path, "plan.json of the submission")->required();
  task->add_option("TASK", c->task, "the array task ($SLURM_ARRAY_TASK_ID)")
      ->required()
      ->check(CLI::NonNegativeNumber);
  return task;
}

int SweepTaskMain(const SweepTaskCommand& c) {
  const RunPoolResult result = RunSweepTask(c.plan_path, c.task, &g_stop_requested);
  for (const std::string& failure : result.failures) std::fprintf(stderr, "%s\n", failure.c_str());
  if (result.interrupted) return 130;
  return result.failures.empty() ? 0 : 1;
}

// mjslam divergence
struct DivergenceCommand {
  std::string run_dir;
  std::vector<int> num_points = {100, 200, 500, 1000, 2000, 5000, 10000, 20000};
  int realisations = 100;
  std::string out;
  std::vector<std::string> pair;
  eval::DivergenceParams params;
};

CLI::App* AddDivergence(CLI::App* cli, DivergenceCommand* c) {
  CLI::App* divergence = cli->add_subcommand(
      "divergence", "The paper's map divergence study (Figs. 6, 7) of a run directory");
  divergence->add_option("RUN_DIR", c->run_dir, "Run directory")->required();
  divergence->add_option("--points", c->num_points, "Numbers of Monte Carlo points #E")
      ->capture_default_str();
  divergence->add_option("--realisations", c->realisations, "Realisations per #E")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  divergence->add_option("--out", c->out, "Output CSV [RUN_DIR/divergence.csv]");
  divergence->add_option("--pair", c->pair,
                         "The two filters to compare [classical selective, else the first two "
                         "with a map]")
      ->expected(2);
  divergence->add_option("--floor-std", c->params.floor_std_m,
                         "Std added to every Gaussian of a filter's map, m (0: its own covariance, the paper's)")
      ->capture_default_str();
  divergence->add_option("--truth-std", c->params.truth_std_m, "Std of the ground truth's Gaussians, m")
      ->capture_default_str();
  divergence->add_option("--weights", c->params.weights,
                         "feature (each feature 1/L) or gaussian (each Gaussian the same)")
      ->capture_default_str();
  divergence->add_option("--line-spacing", c->params.line_spacing_m,
                         "Largest spacing of a line's Gaussians, m")
      ->capture_default_str();
  divergence->add_option("--margin", c->params.margin_m, "Margin of the points' box, m")
      ->capture_default_str();
  return divergence;
}

int DivergenceMain(const DivergenceCommand& c) {
  const std::string out = c.out.empty() ? rundir::PathIn(c.run_dir, rundir::kDivergenceFile) : c.out;
  EvaluateOptions options;
  options.divergence = c.params;
  options.divergence_pair = c.pair;
  options.divergence.ValidateOrThrow();
  WriteDivergenceStudy(c.run_dir, c.num_points, c.realisations, out, options);
  std::fprintf(stderr, "%s: written\n", out.c_str());
  return 0;
}

// mjslam render
struct RenderCommand {
  std::string dir;
  renders::RenderParams params;
  bool no_video = false;
  bool no_plots = false;
  bool quiet = false;
};

CLI::App* AddRender(CLI::App* cli, RenderCommand* c) {
  CLI::App* render = cli->add_subcommand(
      "render", "Render a run directory (final.png, video.mp4, plots, index.html) or a sweep directory");
  render->add_option("DIR", c->dir, "Run directory or sweep directory")->required();
  render->add_option("--width", c->params.width, "Image and video width, pixels")->capture_default_str();
  render->add_option("--height", c->params.height, "Image and video height, pixels")->capture_default_str();
  render->add_option("--fps", c->params.fps, "Video frames per second")->capture_default_str();
  render->add_option("--speedup", c->params.speedup, "Simulated seconds per video second")
      ->capture_default_str();
  render->add_option("--crf", c->params.crf, "H.264 quality, 0 (lossless) .. 51")->capture_default_str();
  render->add_flag("--no-video", c->no_video, "No video.mp4");
  render->add_flag("--no-plots", c->no_plots, "No plots and no index.html");
  render->add_flag("--quiet", c->quiet, "No progress bar");
  return render;
}

int RenderMain(RenderCommand c) {
  if (IsSweepDirectory(c.dir)) {
    RenderSweep(c.dir);
    std::fprintf(stderr, "%s: sweep report written\n", c.dir.c_str());
    return 0;
  }
  c.params.video = !c.no_video;
  c.params.plots = !c.no_plots;
  if (IsImportedRun(c.dir)) {
    const int frames = RenderImportedRun(c.dir, c.params);
    std::fprintf(stderr, "%s: rendered (final.png, %d video frames)\n", c.dir.c_str(), frames);
    return 0;
  }
  RenderOptions options;
  options.show_progress = !c.quiet;
  options.stop_requested = &g_stop_requested;
  const RenderResult rendered = RenderRun(c.dir, c.params, options);
  std::fprintf(stderr, "%s: rendered (%d video frames in %.2f s: %.1f frames/s)\n", c.dir.c_str(),
               rendered.video_frames, rendered.video_wall_s, rendered.video_fps);
  return 0;
}

}  // namespace
}  // namespace mjslam::app

int main(int argc, char** argv) {
  namespace app = mjslam::app;
  // Large blocks (a global map's covariance: tens of MB) come from the heap
  // and go back to it, not to the system: glibc maps every block above its
  // threshold (at most 32 MB) afresh, or trims the heap's top when one is
  // freed, and a join that allocates several faulted in every page of each
  // again.
  mallopt(M_MMAP_THRESHOLD, 1 << 30);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  CLI::App cli{"mjslam: laser EKF-SLAM testbed on a simulated Pioneer 3-DX (MuJoCo)"};
  cli.set_version_flag("--version", app::MjslamVersion() + " (" + app::MjslamGitCommit() + ")");
  cli.require_subcommand(1);
  app::RunCommand run;
  app::ReplayCommand replay;
  app::ImportCommand import;
  app::ConfigOptions config;
  app::EvaluateCommand evaluate;
  app::CalibrateCommand calibrate;
  app::SweepCommand sweep;
  app::SweepTaskCommand sweep_task;
  app::DivergenceCommand divergence;
  app::RenderCommand render;
  const std::string command_line = app::JoinArguments(argc, argv);
  // Each subcommand with the function that runs it.
  const std::vector<std::pair<CLI::App*, std::function<int()>>> commands = {
      {app::AddRun(&cli, &run), [&] { return app::RunMain(*cli.get_subcommand("run"), run, command_line); }},
      {app::AddReplay(&cli, &replay), [&] { return app::ReplayMain(replay, command_line); }},
      {app::AddImport(&cli, &import), [&] { return app::ImportMain(*cli.get_subcommand("import"), import, command_line); }},
      {app::AddConfig(&cli, &config), [&] { return app::ConfigMain(config); }},
      {app::AddEvaluate(&cli, &evaluate), [&] { return app::EvaluateMain(evaluate); }},
      {app::AddCalibrate(&cli, &calibrate), [&] { return app::CalibrateMain(calibrate, command_line); }},
      {app::AddSweep(&cli, &sweep), [&] { return app::SweepMain(*cli.get_subcommand("sweep"), sweep); }},
      {app::AddSweepTask(&cli, &sweep_task), [&] { return app::SweepTaskMain(sweep_task); }},
      {app::AddDivergence(&cli, &divergence), [&] { return app::DivergenceMain(divergence); }},
      {app::AddRender(&cli, &render), [&] { return app::RenderMain(render); }}};
  // CLI11 takes an unknown subcommand for an extra argument and lets a
  // --help after it print the top-level help with status 0.
  if (argc > 1 && argv[1][0] != '-') {
    std::string names;
    bool known = false;
    for (const auto& command : commands) {
      known = known || command.first->get_name() == argv[1];
      names += (names.empty() ? "" : ", ") + command.first->get_name();
    }
    if (!known) {
      std::fprintf(stderr, "mjslam: error: unknown subcommand '%s' (expected one of %s)\n",
                   argv[1], names.c_str());
      return static_cast<int>(CLI::ExitCodes::RequiredError);
    }
  }
  CLI11_PARSE(cli, argc, argv);

  std::signal(SIGINT, app::RequestStop);
  std::signal(SIGTERM, app::RequestStop);
  app::StopWithParent(app::RequestStop);
  try {
    for (const auto& [command, execute] : commands) {
      if (command->parsed()) return execute();
    }
  } catch (const mjslam::Interrupted& interrupted) {
    std::fprintf(stderr, "mjslam: %s (no partial file written)\n", interrupted.what());
    return 130;
  } catch (const std::exception& error) {
    // One problem on the line of its prefix; several (a config's) below it.
    const std::string message = error.what();
    const char* separator = message.find('\n') == std::string::npos ? " " : "\n";
    std::fprintf(stderr, "mjslam: error:%s%s\n", separator, message.c_str());
    // A render stopped by Ctrl-C or SIGTERM is an interrupt, not a failure.
    if (app::g_stop_requested != 0) return 130;
    return 1;
  }
  return 0;
}
