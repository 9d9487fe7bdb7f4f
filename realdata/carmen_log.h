#pragma once

// Reader of CARMEN laser logs (the text format of the CARMEN robot toolkit,
// one message per line; plain or gzip). docs/real_data.md describes the
// messages read and the rules below.
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "common/pose2.h"

namespace mjslam::realdata {

/// One `ODOM` message: the wheel-odometry pose of the robot centre.
struct OdometryMessage {
  /// The message's ipc timestamp, seconds.
  double t_s = 0.0;
  /// x y theta of the robot in the odometry frame: as logged, or, in a log
  /// whose odometry restarts from each scan's corrected pose
  /// (CarmenLog::reanchored), rebuilt from the logged increments.
  Pose2 pose;
  /// Translational and rotational velocity the robot reported (m/s, rad/s).
  double tv_mps = 0.0;
  double rv_radps = 0.0;
  /// Line of the log it came from (1-based).
  int line = 0;
};

/// One laser message (FLASER, RLASER, ROBOTLASER1/2, RAWLASER1..4).
struct LaserMessage {
  /// The message name, e.g. "FLASER".
  std::string kind;
  /// The message's ipc timestamp, seconds.
  double t_s = 0.0;
  /// Ranges as logged, metres, beam 0 first (counter-clockwise).
  std::vector<double> ranges_m;
  /// Bearing of beam 0 and step between beams in the laser frame, radians;
  /// the maximum range, metres. From the message (ROBOTLASER, RAWLASER), or
  /// the rules of CarmenReadOptions (FLASER, RLASER).
  double angle_min_rad = 0.0;
  double angle_increment_rad = 0.0;
  double max_range_m = 0.0;
  /// Whether the message carries poses (FLASER, RLASER, ROBOTLASER).
  bool has_poses = false;
  /// The pose of the laser, and the robot's pose as the message gives it
  /// (CARMEN's "odometry" triple of FLASER, the robot pose of ROBOTLASER).
  Pose2 laser_pose;
  Pose2 robot_pose;
  /// Whether the ODOM message just before it in the log has its timestamp
  /// (the corrected logs write the raw odometry of each scan so), and that
  /// message's pose: the odometry at the scan, whatever the clock's jitter.
  bool has_odometry_at_scan = false;
  Pose2 odometry_at_scan;
  /// Line of the log it came from (1-based).
  int line = 0;
};

/// How to read a log: what the log itself may not say.
struct CarmenReadOptions {
  /// Beam layout of FLASER/RLASER, which carry only the beam count: the
  /// bearing of beam 0, degrees (CARMEN's -90 by default), and the step
  /// between beams, degrees (0: CarmenDefaultStepDeg of the count).
  double angle_min_deg = -90.0;
  double angle_step_deg = 0.0;
  /// Maximum range, metres, for every laser message: when > 0 it replaces
  /// the log's (ROBOTLASER/RAWLASER field, or PARAM robot_front_laser_max,
  /// or the SICK no-return value 81.83 m).
  double max_range_m = 0.0;
  /// A malformed line (wrong field count, a field that is not a number) is
  /// an error naming the line (false, the default) or a counted skip.
  bool skip_bad_lines = false;
  /// Keep the ODOM poses as logged even where the log re-anchors them at
  /// each scan (CarmenLog::reanchored), instead of rebuilding the odometry.
  bool odometry_as_logged = false;
};

/// A whole log: the messages kept, the parameters, and what was skipped.
struct CarmenLog {
  /// The file read.
  std::string path;
  /// PARAM name -> value (text), the last one of each name.
  std::map<std::string, std::string> params;
  /// ODOM messages with a positive timestamp after the previous one's, in
  /// log order.
  std::vector<OdometryMessage> odometry;
  /// Laser messages by kind, each with increasing timestamps.
  std::map<std::string, std::vector<LaserMessage>> lasers;
  /// Lines not used, by reason (e.g. "ODOM: timestamp <= 0", "NEFF: not
  /// read", "bad line"), and the first bad lines' messages.
  std::map<std::string, int> skipped;
  std::vector<std::string> bad_lines;
  /// Lines read.
  int num_lines = 0;
  /// What the reader did besides skipping lines, one sentence each (e.g.
  /// timestamps of low precision spread in line order).
  std::vector<std::string> warnings;
  /// Whether the log re-anchors its odometry: an ODOM line right after a
  /// laser message repeats the message's robot pose (the corrected logs
  /// write each scan's corrected pose so, with timestamp 0), and the ODOM
  /// lines after it continue from that pose, o(t) = C_k (+) R(t_k)^-1 (+)
  /// R(t), R the wheel odometry. Such a copy is skipped, counted, and
  /// starts the next segment; unless odometry_as_logged, the odometry is
  /// rebuilt by chaining the logged increments within each segment, in
  /// log order (timestamps that run backwards included).
  bool reanchored = false;
};

/// The angular step CARMEN's FLASER/RLASER imply for `num_beams`, degrees:
/// 1 for 180 or 181 beams, 0.5 for 360 or 361, 0.25 for 720 or 721, else
/// 180 / (num_beams - 1) (a 180 deg fan, both ends included).
double CarmenDefaultStepDeg(int num_beams);

/// Reads a CARMEN log, plain or gzip (zlib reads both). Throws
/// std::runtime_error "PATH:LINE: ..." for a malformed line (unless
/// options.skip_bad_lines) and "PATH: ..." when the file cannot be read.
/// Timestamps must increase within a message stream: an ODOM or laser
/// message whose timestamp is <= 0 or before the previous one of its kind
/// (the corrected logs' pose lines, corrupt stamps) is skipped and counted.
/// Messages that share their timestamp with the one before (a log printed
/// with few significant digits, e.g. 1.13486e+09) are kept: the k messages
/// of a stream stamped T get the times T + i (T' - T) / k in line order, T'
/// the stream's next stamp (after its last stamp: its mean step), and a
/// warning says how many (CarmenLog::warnings).
CarmenLog ReadCarmenLog(const std::string& path, const CarmenReadOptions& options = {});

/// The longest line the log readers accept, bytes (a RAWLASER line of 1081
/// beams is about 10 KB): a longer one is a bad line.
inline constexpr std::size_t kMaxLogLineBytes = std::size_t{1} << 20;

/// Throws std::runtime_error "PATH: ..." unless `path` names a regular file:
/// a pipe, FIFO or device can be read only once (a format sniff would eat
/// its start) or never ends (/dev/zero).
void RequireRegularFile(const std::string& path);

/// `text` as an error message quotes it: as is up to 60 bytes, else its
/// first 60 bytes and "... (N bytes)".
std::string Shown(const std::string& text);

/// The whitespace-separated fields of one line of a text log.
std::vector<std::string> SplitLogFields(const std::string& line);

/// The skip counts of `log` as one line each ("NEFF: not read: 910 lines").
std::vector<std::string> SkipReport(const CarmenLog& log);

}  // namespace mjslam::realdata
