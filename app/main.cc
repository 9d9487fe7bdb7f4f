// mjslam: the command line. One function adds each subcommand's options and
// one runs it; main() builds the CLI and dispatches. With the tests, the only
// place that catches errors.
#include <csignal>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/evaluate.h"
#include "app/render_run.h"
#include "app/replay.h"
#include "app/run.h"
#include "app/run_config.h"
#include "app/sweep.h"
#include "app/version.h"
#include "common/interrupt.h"
#include "config/config.h"
#include "rundir/layout.h"

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
  if (result.status != "completed") return 130;
  if (!c.no_evaluate) EvaluateRunDirectory(options.out_dir, EvaluateOptions{});
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
  Replay(config, c.options);
  std::fprintf(stderr, "%s: replay completed\n", c.options.out_dir.c_str());
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

// mjslam evaluate
struct EvaluateCommand {
  std::string run_dir;
  EvaluateOptions options;
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
  return evaluate;
}

int EvaluateMain(const EvaluateCommand& c) {
  const RunEvaluation result = EvaluateRunDirectory(c.run_dir, c.options);
  std::printf("%-10s %8s %8s %8s %9s %8s %9s %6s %6s\n", "filter", "in2s_x", "in2s_y", "in2s_th",
              "mean_nees", "matched", "dupl", "unm", "incons");
  for (std::size_t i = 0; i < result.pose.size(); ++i) {
    const auto& p = result.pose[i];
    const auto& m = result.map[i];
    std::printf("%-10s %8.3f %8.3f %8.3f %9.3f %8.3f %9d %6d %6d\n",
                rundir::FilterNames()[i].c_str(), p.inside_2sigma(0), p.inside_2sigma(1),
                p.inside_2sigma(2), p.mean_nees, m.matched_fraction, m.num_duplicates,
                m.num_unmatched_estimates, m.num_inconsistent);
  }
  if (result.has_divergence) {
    std::printf("divergence: classical||selective %.4g, selective||classical %.4g, "
                "classical||truth %.4g, selective||truth %.4g\n",
                result.divergence.classical_selective, result.divergence.selective_classical,
                result.divergence.classical_truth, result.divergence.selective_truth);
  }
  return 0;
}

// mjslam sweep
struct SweepCommand {
  ConfigOptions config;
  SweepOptions options;
  double duration_s = 0.0;
  bool quiet = false;
};

CLI::App* AddSweep(CLI::App* cli, SweepCommand* c) {
  CLI::App* sweep = cli->add_subcommand(
      "sweep", "Monte Carlo runs with seeds run.seed + i, evaluated and aggregated");
  AddConfigOptions(sweep, &c->config, "Override any config key");
  sweep->add_option("--runs", c->options.runs, "Number of runs")->required()->check(CLI::PositiveNumber);
  sweep->add_option("--jobs", c->options.jobs, "Runs at a time (0: one per core)")
      ->capture_default_str()
      ->check(NonNegativeInteger());
  sweep->add_option("--out", c->options.out_dir, "Sweep directory")->required();
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
  sweep->add_flag("--quiet", c->quiet, "No line per finished run");
  return sweep;
}

int SweepMain(const CLI::App& sweep, SweepCommand c) {
  if (sweep.count("--duration") > 0) {
    c.config.overrides.push_back("run.duration_s=" + ValueText(c.duration_s));
  }
  const RunConfig config = LoadRunConfig(c.config.path, c.config.overrides);
  c.options.program = std::filesystem::read_symlink("/proc/self/exe").string();
  c.options.verbose = !c.quiet;
  c.options.stop_requested = &g_stop_requested;
  const SweepResult result = RunSweep(config, c.options);
  if (result.interrupted) {
    std::fprintf(stderr, "%s: interrupted; run the same command again to resume\n",
                 c.options.out_dir.c_str());
    return 130;
  }
  for (const std::string& name : rundir::FilterNames()) {
    const auto& f = result.summary["filters"][name];
    std::printf("%-10s ANEES inside the bounds for %.3f of the steps (above %.3f, below "
                "%.3f), mean ANEES %.3f: %s\n",
                name.c_str(), f["fraction_inside"].get<double>(), f["fraction_above"].get<double>(),
                f["fraction_below"].get<double>(),
                f["mean_anees"].is_number() ? f["mean_anees"].get<double>() : 0.0,
                f["verdict"].get<std::string>().c_str());
  }
  std::fprintf(stderr, "%s: %d runs made, %d kept\n", c.options.out_dir.c_str(), result.runs_made,
               result.runs_kept);
  return 0;
}

// mjslam divergence
struct DivergenceCommand {
  std::string run_dir;
  std::vector<int> num_points = {100, 200, 500, 1000, 2000, 5000, 10000, 20000};
  int realisations = 100;
  std::string out;
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
  return divergence;
}

int DivergenceMain(const DivergenceCommand& c) {
  const std::string out = c.out.empty() ? rundir::PathIn(c.run_dir, rundir::kDivergenceFile) : c.out;
  WriteDivergenceStudy(c.run_dir, c.num_points, c.realisations, out);
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
  CLI::App cli{"mjslam: laser EKF-SLAM testbed on a simulated Pioneer 3-DX (MuJoCo)"};
  cli.set_version_flag("--version", app::MjslamVersion() + " (" + app::MjslamGitCommit() + ")");
  cli.require_subcommand(1);
  app::RunCommand run;
  app::ReplayCommand replay;
  app::ConfigOptions config;
  app::EvaluateCommand evaluate;
  app::SweepCommand sweep;
  app::DivergenceCommand divergence;
  app::RenderCommand render;
  const std::string command_line = app::JoinArguments(argc, argv);
  // Each subcommand with the function that runs it.
  const std::vector<std::pair<CLI::App*, std::function<int()>>> commands = {
      {app::AddRun(&cli, &run), [&] { return app::RunMain(*cli.get_subcommand("run"), run, command_line); }},
      {app::AddReplay(&cli, &replay), [&] { return app::ReplayMain(replay, command_line); }},
      {app::AddConfig(&cli, &config), [&] { return app::ConfigMain(config); }},
      {app::AddEvaluate(&cli, &evaluate), [&] { return app::EvaluateMain(evaluate); }},
      {app::AddSweep(&cli, &sweep), [&] { return app::SweepMain(*cli.get_subcommand("sweep"), sweep); }},
      {app::AddDivergence(&cli, &divergence), [&] { return app::DivergenceMain(divergence); }},
      {app::AddRender(&cli, &render), [&] { return app::RenderMain(render); }}};
  CLI11_PARSE(cli, argc, argv);

  std::signal(SIGINT, app::RequestStop);
  std::signal(SIGTERM, app::RequestStop);
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
