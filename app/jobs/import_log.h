#pragma once

#include <limits>
#include <string>
#include <vector>

#include "app/engine/run_config.h"
#include "realdata/breezyslam_log.h"
#include "realdata/carmen_log.h"
#include "realdata/relations.h"

namespace mjslam::app {

/// Inputs of `mjslam import` (docs/real_data.md).
struct ImportOptions {
  /// The CARMEN log, plain or gzip.
  std::string log_path;
  /// The run directory to write.
  std::string out_dir;
  std::string config_path;
  std::string command_line;
  /// The log's format: "carmen", "breezyslam" or "auto" (breezyslam when
  /// realdata::LooksLikeBreezySlamLog, else carmen).
  std::string format = "auto";
  /// How to read a CARMEN log (beam layout, maximum range, bad lines); its
  /// max_range_m, when > 0, also replaces a BreezySLAM log's.
  realdata::CarmenReadOptions read;
  /// The rover and laser of a BreezySLAM log.
  realdata::BreezySlamOptions breezyslam;
  /// The laser message stream to use (FLASER, RLASER, ROBOTLASER1, ...);
  /// empty: the first of FLASER, ROBOTLASER1, RAWLASER1 the log has.
  std::string laser;
  /// Distance of the laser ahead of the robot centre, metres; NaN: the log's
  /// PARAM robot_frontlaser_offset (robot_rearlaser_offset for RLASER), or 0.
  double laser_offset_m = std::numeric_limits<double>::quiet_NaN();
  /// Whether the laser messages' poses are the reference trajectory: "auto"
  /// (when they are not the odometry: more than 5 cm or 0.05 rad from it at
  /// some scan), "yes" or "no".
  std::string reference = "auto";
  /// The relations file of the log (Kuemmerle et al. 2009), optional, with
  /// the offset from its timestamps to the log's (NaN: searched with
  /// realdata::BestTimeOffset) and the matching tolerance, seconds. Kept in
  /// the manifest for `mjslam evaluate`.
  std::string relations_path;
  double time_offset_s = std::numeric_limits<double>::quiet_NaN();
  double tolerance_s = 0.006;
  /// The most candidate offsets (relation times x scans) the search may
  /// hold, 8 bytes each (realdata::BestTimeOffset).
  std::size_t max_offset_candidates = realdata::kMaxOffsetCandidates;
  /// Read and check everything (the log, the relations, the offset search,
  /// every value written), then return without writing (the fuzz target).
  bool check_only = false;
};

/// What an import read and wrote, for the command's report.
struct ImportReport {
  std::string laser;
  int num_beams = 0;
  int num_scans = 0;
  int num_odometry = 0;
  int num_steps = 0;
  bool has_reference = false;
  /// Whether the odometry was rebuilt from the increments of a log that
  /// restarts it at each scan (realdata::CarmenLog::reanchored).
  bool odometry_rebuilt = false;
  double time_offset_s = 0.0;
  /// Whether a stop request ended the replay (its rows so far written, the
  /// manifest "interrupted").
  bool interrupted = false;
  /// realdata::SkipReport of the log, plus the scans left out by the import.
  std::vector<std::string> skipped;
  /// What the reader did to the log besides skipping lines (e.g. timestamps
  /// of low precision spread in line order), one sentence each.
  std::vector<std::string> warnings;
};

/// `mjslam import`: reads a CARMEN or BreezySLAM log and writes a run directory that
/// replay, evaluate and render understand, then runs both filters on it:
/// config.yaml (`config` with laser.num_beams, fov_deg and max_range_m of
/// the log), manifest.json (mode "import", the source, the counts, the
/// laser mount, the relations and matching), scans.csv (ranges at or past
/// the maximum, or <= 0, become no-return at the maximum; no true pose),
/// reference.csv (when the log has a reference), trajectory.csv and the
/// maps. One step per odometry message and per scan, in time order; the
/// odometry at a scan is interpolated between its neighbours and given for
/// frame R (control_point_offset_m ahead of the robot centre), its frame
/// placed so that it starts at the reference's first pose. Throws
/// std::runtime_error naming the file and line of bad input.
ImportReport ImportLog(RunConfig config, const ImportOptions& options);

/// Throws std::runtime_error naming the option and its value when an option
/// of `options` is out of its range (docs/commands.md): a NaN, a negative
/// step or tolerance, an infinite offset.
void CheckImportOptions(const ImportOptions& options);

}  // namespace mjslam::app
