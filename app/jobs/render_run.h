#pragma once

#include <csignal>
#include <string>

#include "renders/render_params.h"

namespace mjslam::app {

/// How `mjslam render` was asked to render, beyond RenderParams.
struct RenderOptions {
  /// Draw a progress bar on a terminal.
  bool show_progress = true;
  /// Set asynchronously (by a signal handler) to stop early: the video is
  /// then not written (no partial file) and RenderRun throws.
  const volatile std::sig_atomic_t* stop_requested = nullptr;
};

/// What a render produced and how fast.
struct RenderResult {
  /// Frames of video.mp4 (0 without a video).
  int video_frames = 0;
  /// Wall time of the video (rendering and encoding), seconds, and frames per
  /// second of wall time.
  double video_wall_s = 0.0;
  double video_fps = 0.0;
};

/// Renders a run directory from its files (no re-simulation): final.png (the
/// whole run: paths, both final maps, the last scan), video.mp4 (when
/// params.video; one frame per params.speedup / params.fps simulated
/// seconds, maps in the last frame only, since the run keeps only the final
/// maps), the plots and index.html (when params.plots, through
/// renders/report.py). Reads config.yaml (world, robot, laser layout),
/// trajectory.csv, scans.csv, map_*.csv and, when present, explorer.csv.
/// Every output is written to a temporary name and renamed. Throws
/// std::runtime_error naming the file (and column) that is missing or bad.
RenderResult RenderRun(const std::string& run_dir, const renders::RenderParams& params,
                       const RenderOptions& options);

/// Writes the plots and index.html of a sweep directory (DIR/summary.json,
/// DIR/nees.csv, DIR/divergence.csv, DIR/runs/*) through renders/report.py.
/// Throws std::runtime_error when the script fails.
void RenderSweep(const std::string& sweep_dir);

/// True when `dir` looks like a sweep directory: no trajectory.csv, and a
/// runs/ folder holding at least one folder (a sweep's runs: run_000, ...).
bool IsSweepDirectory(const std::string& dir);

}  // namespace mjslam::app
