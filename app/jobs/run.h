#pragma once

#include <csignal>
#include <optional>
#include <string>
#include <vector>

#include "app/engine/cpu_profile.h"
#include "app/engine/run_config.h"
#include "rundir/summary.h"

namespace mjslam::app {

/// How `mjslam run` was asked to run, beyond the config.
struct RunOptions {
  /// The run directory; created if missing, its files replaced.
  std::string out_dir;
  /// The config file the run was loaded from and the command line, for the
  /// manifest.
  std::string config_path;
  std::string command_line;
  /// Draw a progress bar on a terminal.
  bool show_progress = true;
  /// Render video.mp4 as the run goes (config.render's size and rate).
  bool render_video = false;
  /// Set asynchronously (by a signal handler) to stop the run early; the run
  /// then ends cleanly with status "interrupted".
  const volatile std::sig_atomic_t* stop_requested = nullptr;
};

/// How a run ended.
struct RunResult {
  /// "completed" or "interrupted" ("failed" runs throw).
  std::string status;
  int steps = 0;
  double sim_time_s = 0.0;
  /// Frames of video.mp4 rendered as the run went (0: none), and frames per
  /// second of the wall time spent rendering and encoding them.
  int video_frames = 0;
  double video_fps = 0.0;
  /// CPU seconds by phase of the run (PhaseCpu; `mjslam run --profile`).
  PhaseCpu cpu;
  /// One line per filter whose innovations showed it inconsistent
  /// (summary.json, filters.<f>.innovation_check), for the user to see.
  std::vector<std::string> warnings;
};

/// Runs one closed-loop simulation (ClosedLoop): MuJoCo steps the robot, the
/// laser is cast at its rate, both filters run on every record, the driver
/// steers. Writes config.yaml, manifest.json, trajectory.csv, scans.csv,
/// explorer.csv (explorer only), map_classical.csv, map_selective.csv and
/// summary.json into `options.out_dir` (docs/run_directory.md). On an error
/// the files keep every complete row so far, the manifest records the
/// failure, and the error is rethrown.
RunResult RunSimulation(const RunConfig& config, const RunOptions& options);

/// One warning line per filter of `summary` whose innovation check found it
/// inconsistent: the filter, the time it lost consistency with its own
/// innovations, the scans that copied mapped structure (if any), and the key
/// to look at.
std::vector<std::string> InnovationWarnings(const rundir::RunSummary& summary);

/// The line `mjslam run` prints when the filters assume another range noise
/// (slam.features.range_noise_std_m) than the simulated laser has
/// (laser.range_noise_std_m); none when they agree. The two are separate on
/// purpose (a mismatched model is an experiment), so this is a note, not an
/// error.
std::optional<std::string> RangeNoiseNote(const RunConfig& config);

}  // namespace mjslam::app
