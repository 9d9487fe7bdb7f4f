#pragma once

// Reader of the logs of BreezySLAM's examples (the Mines ParisTech rover of
// CoreSLAM: two wheel encoders and a Hokuyo URG-04LX), read into the form of
// a CARMEN log so that `mjslam import` treats both alike. docs/real_data.md
// describes the format and the rover.
#include <string>

#include "realdata/carmen_log.h"

namespace mjslam::realdata {

/// The message name the scans of a BreezySLAM log get in CarmenLog::lasers.
inline constexpr char kBreezySlamLaser[] = "HOKUYO";

/// What a BreezySLAM log does not say: the rover and its laser. The defaults
/// are those of BreezySLAM's examples/mines.py (the Rover and MinesLaser
/// classes) and of its URG04LX laser class.
struct BreezySlamOptions {
  /// Wheel radius, half the axle length (metres), encoder ticks per wheel
  /// revolution.
  double wheel_radius_m = 0.077;
  double half_axle_m = 0.165;
  int ticks_per_revolution = 2000;
  /// Beams per scan, over `fov_deg`, beam 0 at -fov/2 (right), counter-
  /// clockwise; readings in mm, 0 for none.
  int num_beams = 682;
  double fov_deg = 240.0;
  /// Maximum range, metres: readings at or past it are no return.
  double max_range_m = 4.0;
  /// Beams at each end that BreezySLAM leaves out (its detection margin:
  /// beams 0..margin and num_beams - margin .. num_beams - 1), read as no
  /// return.
  int margin_beams = 70;
  /// Distance of the laser ahead of the wheel axle's centre, metres (written
  /// as PARAM robot_frontlaser_offset).
  double laser_offset_m = 0.145;
};

/// The fields of a BreezySLAM log line: timestamp (µs), one field not used,
/// the left and right wheels' tick counts, 20 fields not used, the ranges,
/// and one trailing field not used (mines.py drops it).
int BreezySlamFieldsPerLine(int num_beams);

/// Reads a BreezySLAM log: one line per scan. The odometry is integrated
/// from the tick counts (one OdometryMessage per line, starting at the
/// origin; per line the wheels turn by 2 pi dticks / ticks_per_revolution,
/// the centre moves r (phi_l + phi_r) / 2 along the mean heading of the step
/// and turns r (phi_r - phi_l) / (2 half_axle)); the scans are
/// kBreezySlamLaser messages, each with its line's odometry. Throws
/// std::runtime_error "PATH:LINE: ..." for a line with the wrong number of
/// fields (a truncated line), a field that is not an integer, or a
/// timestamp not after the line before; "PATH: ..." when the file cannot
/// be read or holds no line.
CarmenLog ReadBreezySlamLog(const std::string& path, const BreezySlamOptions& options = {});

/// Whether the file's first line has the field count of a BreezySLAM log
/// line (BreezySlamFieldsPerLine of options.num_beams), with integers for
/// the timestamp, the ticks and the ranges.
bool LooksLikeBreezySlamLog(const std::string& path, const BreezySlamOptions& options = {});

}  // namespace mjslam::realdata
