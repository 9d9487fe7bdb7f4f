#pragma once

#include <string>

#include "app/engine/run_config.h"
#include "rundir/manifest.h"
#include "rundir/recording.h"

namespace mjslam::app {

/// Inputs of `mjslam replay`.
struct ReplayOptions {
  /// scans.csv of an earlier run.
  std::string scans_path;
  /// Its trajectory.csv; empty: the one beside `scans_path`.
  std::string trajectory_path;
  /// Where to write the outputs.
  std::string out_dir;
  std::string config_path;
  std::string command_line;
};

/// Runs both filters on recorded data, without the simulator: the records are
/// rebuilt from the trajectory (true pose for the initial pose, odometry,
/// held command) and the scans (ranges at the maximum are no-return). The
/// laser mount comes from the manifest.json beside the scans when there is
/// one, else from the true poses of the laser and of R at the first scan.
/// Writes config.yaml, manifest.json, trajectory.csv (same columns as a run)
/// and the two maps. Given the same config, the filter columns equal those
/// of the original run except the timings. Throws std::runtime_error naming
/// the file, line and column of bad input. Returns false when a stop request
/// (common/interrupt.h) ended it: the rows so far are written, whole, and
/// the manifest says "interrupted".
bool Replay(const RunConfig& config, const ReplayOptions& options);

/// The part of Replay after its inputs are read, for `mjslam replay` and
/// `mjslam import`: runs both filters over `recording` and writes
/// trajectory.csv and the maps into `dir` (locked by the caller), records
/// the laser mount in `manifest` (so that the directory can be replayed in
/// turn) and finishes it ("completed", or "failed" with the error, which is
/// rethrown). On a stop request it stops at the next step, writes the maps
/// of the steps done, finishes the manifest "interrupted" and returns false.
bool ReplayRecording(const RunConfig& config, const rundir::Recording& recording,
                     const std::string& dir, rundir::ManifestWriter* manifest);

}  // namespace mjslam::app
