// mjslam: the command line. Parses arguments, loads the config, runs, and is
// (with the tests) the only place that catches errors.
#include <csignal>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/evaluate.h"
#include "app/render_run.h"
#include "app/replay.h"
#include "app/run.h"
#include "app/run_config.h"
#include "app/run_files.h"
#include "app/sweep.h"
#include "config/config.h"

namespace {

volatile std::sig_atomic_t g_stop_requested = 0;

void RequestStop(int /*signal*/) { g_stop_requested = 1; }

std::string JoinArguments(int argc, char** argv) {
  std::string text;
  for (int i = 0; i < argc; ++i) text += (i ? " " : "") + std::string(argv[i]);
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  using mjslam::app::RunConfig;
  CLI::App cli{"mjslam: laser EKF-SLAM testbed on a simulated Pioneer 3-DX (MuJoCo)"};
  cli.set_version_flag("--version", mjslam::app::MjslamVersion() + " (" +
                                        mjslam::app::MjslamGitCommit() + ")");
  cli.require_subcommand(1);
  const std::string default_config = std::string(MJSLAM_SOURCE_DIR) + "/configs/default.yaml";

  // mjslam run
  CLI::App* run = cli.add_subcommand("run", "Run one closed-loop simulation and write a run directory");
  std::string config_path = default_config;
  std::string world;
  std::string out_dir;
  std::uint64_t seed = 0;
  double duration_s = 0.0;
  std::vector<std::string> overrides;
  bool quiet = false;
  run->add_option("--config", config_path, "YAML config file")->capture_default_str();
  run->add_option("--world", world, "World MJCF file (overrides run.world)");
  run->add_option("--seed", seed, "Root random seed (overrides run.seed)");
  run->add_option("--duration", duration_s, "Simulated seconds (overrides run.duration_s)");
  run->add_option("--out", out_dir, "Run directory [runs/<world>-seed<seed>]");
  run->add_option("--set", overrides, "Override any config key: --set laser.range_noise_std_m=0")
      ->type_name("KEY=VALUE");
  run->add_flag("--quiet", quiet, "No progress bar");
  bool no_render = false;
  run->add_flag("--no-render", no_render, "Do not render at the end, whatever render.enabled says");
  bool no_evaluate = false;
  run->add_flag("--no-evaluate", no_evaluate,
                "Do not evaluate at the end (ground_truth_map.csv, metrics in summary.json)");

  // mjslam replay
  CLI::App* replay =
      cli.add_subcommand("replay", "Run both filters on the scans and trajectory of an earlier run");
  std::string scans_path;
  std::string trajectory_path;
  replay->add_option("--scans", scans_path, "scans.csv of an earlier run")->required();
  replay->add_option("--trajectory", trajectory_path,
                     "Its trajectory.csv [the one beside --scans]");
  replay->add_option("--config", config_path, "YAML config file")->capture_default_str();
  replay->add_option("--out", out_dir, "Output directory")->required();
  replay->add_option("--set", overrides, "Override any config key")->type_name("KEY=VALUE");

  // mjslam config
  CLI::App* show_config =
      cli.add_subcommand("config", "Print the resolved config (defaults, file, overrides) as YAML");
  show_config->add_option("--config", config_path, "YAML config file")->capture_default_str();
  show_config->add_option("--set", overrides, "Override any config key")->type_name("KEY=VALUE");

  // mjslam evaluate
  CLI::App* evaluate = cli.add_subcommand(
      "evaluate", "Ground truth, pose and map metrics of a run directory, into summary.json");
  std::string run_dir;
  mjslam::app::EvaluateOptions evaluate_options;
  evaluate->add_option("RUN_DIR", run_dir, "Run directory")->required();
  evaluate->add_option("--divergence-points", evaluate_options.divergence_points,
                       "Monte Carlo points of the map divergence (0: none)")
      ->capture_default_str();
  evaluate->add_option("--realisations", evaluate_options.divergence_realisations,
                       "Realisations of the divergence (their mean is reported)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);

  // mjslam sweep
  CLI::App* sweep = cli.add_subcommand(
      "sweep", "Monte Carlo runs with seeds run.seed + i, evaluated and aggregated");
  mjslam::app::SweepOptions sweep_options;
  std::vector<int> study_points;
  sweep->add_option("--config", config_path, "YAML config file")->capture_default_str();
  sweep->add_option("--runs", sweep_options.runs, "Number of runs")->required()->check(CLI::PositiveNumber);
  sweep->add_option("--jobs", sweep_options.jobs, "Runs at a time (0: one per core)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  sweep->add_option("--out", out_dir, "Sweep directory")->required();
  sweep->add_option("--set", overrides, "Override any config key")->type_name("KEY=VALUE");
  sweep->add_option("--duration", duration_s, "Simulated seconds of each run (overrides run.duration_s)");
  sweep->add_option("--divergence-points", sweep_options.divergence_points,
                    "Map divergence points of each run's evaluation (0: none)")
      ->capture_default_str();
  sweep->add_option("--divergence-study", study_points,
                    "Also write DIR/divergence.csv from the first run for these #E (e.g. 100 1000 20000)");
  sweep->add_option("--study-realisations", sweep_options.divergence_study_realisations,
                    "Realisations per #E of --divergence-study")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  sweep->add_flag("--quiet", quiet, "No line per finished run");

  // mjslam divergence
  CLI::App* divergence = cli.add_subcommand(
      "divergence", "The paper's map divergence study (Figs. 6, 7) of a run directory");
  std::vector<int> num_points = {100, 200, 500, 1000, 2000, 5000, 10000, 20000};
  int realisations = 100;
  std::string divergence_out;
  divergence->add_option("RUN_DIR", run_dir, "Run directory")->required();
  divergence->add_option("--points", num_points, "Numbers of Monte Carlo points #E")
      ->capture_default_str();
  divergence->add_option("--realisations", realisations, "Realisations per #E")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  divergence->add_option("--out", divergence_out, "Output CSV [RUN_DIR/divergence.csv]");
  // mjslam render
  CLI::App* render = cli.add_subcommand(
      "render", "Render a run directory (final.png, video.mp4, plots, index.html) or a sweep directory");
  std::string render_dir;
  std::vector<std::string> render_overrides;
  mjslam::renders::RenderParams render_params;
  render->add_option("DIR", render_dir, "Run directory or sweep directory")->required();
  render->add_option("--width", render_params.width, "Image and video width, pixels")->capture_default_str();
  render->add_option("--height", render_params.height, "Image and video height, pixels")->capture_default_str();
  render->add_option("--fps", render_params.fps, "Video frames per second")->capture_default_str();
  render->add_option("--speedup", render_params.speedup, "Simulated seconds per video second")
      ->capture_default_str();
  render->add_option("--crf", render_params.crf, "H.264 quality, 0 (lossless) .. 51")->capture_default_str();
  bool render_no_video = false;
  bool render_no_plots = false;
  render->add_flag("--no-video", render_no_video, "No video.mp4");
  render->add_flag("--no-plots", render_no_plots, "No plots and no index.html");
  render->add_flag("--quiet", quiet, "No progress bar");

  CLI11_PARSE(cli, argc, argv);

  std::signal(SIGINT, RequestStop);
  std::signal(SIGTERM, RequestStop);
  try {
    if (run->parsed()) {
      // Command-line options are overrides like --set, applied last.
      if (!world.empty()) overrides.push_back("run.world=" + world);
      if (run->count("--seed") > 0) overrides.push_back("run.seed=" + std::to_string(seed));
      if (run->count("--duration") > 0) {
        overrides.push_back("run.duration_s=" + mjslam::ValueText(duration_s));
      }
      const RunConfig config = mjslam::app::LoadRunConfig(config_path, overrides);
      mjslam::app::RunOptions options;
      options.out_dir = out_dir;
      if (options.out_dir.empty()) {
        const std::string stem = std::filesystem::path(config.run.world).stem().string();
        options.out_dir = "runs/" + stem + "-seed" + std::to_string(config.run.seed);
      }
      options.config_path = config_path;
      options.command_line = JoinArguments(argc, argv);
      options.show_progress = !quiet;
      options.stop_requested = &g_stop_requested;
      // The video is rendered as the run goes; the final image, the plots and
      // the page come after the evaluation, from the run's files.
      const bool render = config.render.enabled && !no_render;
      options.render_video = render && config.render.video;
      const mjslam::app::RunResult result = mjslam::app::RunSimulation(config, options);
      std::fprintf(stderr, "%s: %s after %d steps (%.1f s simulated)\n", options.out_dir.c_str(),
                   result.status.c_str(), result.steps, result.sim_time_s);
      if (result.status == "completed" && !no_evaluate) {
        mjslam::app::EvaluateRunDirectory(options.out_dir, mjslam::app::EvaluateOptions{});
      }
      if (result.status == "completed" && render) {
        mjslam::app::RenderOptions render_options;
        render_options.show_progress = !quiet;
        render_options.stop_requested = &g_stop_requested;
        mjslam::renders::RenderParams after_run = config.render;
        after_run.video = false;  // already written during the run
        mjslam::app::RenderRun(options.out_dir, after_run, render_options);
        std::fprintf(stderr, "%s: rendered (%d video frames during the run, %.0f frames/s)\n",
                     options.out_dir.c_str(), result.video_frames, result.video_fps);
      }
      return result.status == "completed" ? 0 : 130;
    }
    if (show_config->parsed()) {
      std::fputs(mjslam::config::ToYaml(mjslam::app::LoadRunConfig(config_path, overrides)).c_str(),
                 stdout);
      return 0;
    }
    if (render->parsed()) {
      if (mjslam::app::IsSweepDirectory(render_dir)) {
        mjslam::app::RenderSweep(render_dir);
        std::fprintf(stderr, "%s: sweep report written\n", render_dir.c_str());
        return 0;
      }
      render_params.video = !render_no_video;
      render_params.plots = !render_no_plots;
      mjslam::app::RenderOptions render_options;
      render_options.show_progress = !quiet;
      render_options.stop_requested = &g_stop_requested;
      const mjslam::app::RenderResult rendered =
          mjslam::app::RenderRun(render_dir, render_params, render_options);
      std::fprintf(stderr, "%s: rendered (%d video frames in %.2f s: %.1f frames/s)\n", render_dir.c_str(),
                   rendered.video_frames, rendered.video_wall_s, rendered.video_fps);
      return 0;
    }
    if (replay->parsed()) {
      const RunConfig config = mjslam::app::LoadRunConfig(config_path, overrides);
      mjslam::app::ReplayOptions options;
      options.scans_path = scans_path;
      options.trajectory_path = trajectory_path;
      options.out_dir = out_dir;
      options.config_path = config_path;
      options.command_line = JoinArguments(argc, argv);
      mjslam::app::Replay(config, options);
      std::fprintf(stderr, "%s: replay completed\n", out_dir.c_str());
      return 0;
    }
    if (evaluate->parsed()) {
      const mjslam::app::RunEvaluation result =
          mjslam::app::EvaluateRunDirectory(run_dir, evaluate_options);
      std::printf("%-10s %8s %8s %8s %9s %8s %9s %6s %6s\n", "filter", "in2s_x", "in2s_y",
                  "in2s_th", "mean_nees", "matched", "dupl", "unm", "incons");
      for (std::size_t i = 0; i < result.pose.size(); ++i) {
        const auto& p = result.pose[i];
        const auto& m = result.map[i];
        std::printf("%-10s %8.3f %8.3f %8.3f %9.3f %8.3f %9d %6d %6d\n",
                    mjslam::app::FilterNames()[i].c_str(), p.inside_2sigma(0),
                    p.inside_2sigma(1), p.inside_2sigma(2), p.mean_nees, m.matched_fraction,
                    m.num_duplicates, m.num_unmatched_estimates, m.num_inconsistent);
      }
      if (result.has_divergence) {
        std::printf("divergence: classical||selective %.4g, selective||classical %.4g, "
                    "classical||truth %.4g, selective||truth %.4g\n",
                    result.divergence.classical_selective, result.divergence.selective_classical,
                    result.divergence.classical_truth, result.divergence.selective_truth);
      }
      return 0;
    }
    if (sweep->parsed()) {
      if (sweep->count("--duration") > 0) {
        overrides.push_back("run.duration_s=" + mjslam::ValueText(duration_s));
      }
      const RunConfig config = mjslam::app::LoadRunConfig(config_path, overrides);
      sweep_options.out_dir = out_dir;
      sweep_options.program = std::filesystem::read_symlink("/proc/self/exe").string();
      sweep_options.divergence_study_points = study_points;
      sweep_options.verbose = !quiet;
      sweep_options.stop_requested = &g_stop_requested;
      const mjslam::app::SweepResult result = mjslam::app::RunSweep(config, sweep_options);
      if (result.interrupted) {
        std::fprintf(stderr, "%s: interrupted; run the same command again to resume\n",
                     out_dir.c_str());
        return 130;
      }
      for (const std::string& name : mjslam::app::FilterNames()) {
        const auto& f = result.summary["filters"][name];
        std::printf("%-10s ANEES inside the bounds for %.3f of the steps (above %.3f, below "
                    "%.3f), mean ANEES %.3f: %s\n",
                    name.c_str(), f["fraction_inside"].get<double>(),
                    f["fraction_above"].get<double>(), f["fraction_below"].get<double>(),
                    f["mean_anees"].is_number() ? f["mean_anees"].get<double>() : 0.0,
                    f["verdict"].get<std::string>().c_str());
      }
      std::fprintf(stderr, "%s: %d runs made, %d kept\n", out_dir.c_str(), result.runs_made,
                   result.runs_kept);
      return 0;
    }
    if (divergence->parsed()) {
      const std::string out = divergence_out.empty() ? run_dir + "/divergence.csv" : divergence_out;
      mjslam::app::WriteDivergenceStudy(run_dir, num_points, realisations, out);
      std::fprintf(stderr, "%s: written\n", out.c_str());
      return 0;
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "mjslam: error:\n%s\n", error.what());
    // A render stopped by Ctrl-C or SIGTERM is an interrupt, not a failure.
    if (g_stop_requested != 0) return 130;
    return 1;
  }
  return 0;
}
