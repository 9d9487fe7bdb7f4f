#include "app/jobs/import_log.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>

#include "app/jobs/replay.h"
#include "app/jobs/version.h"
#include "common/interrupt.h"
#include "common/params.h"
#include "config/config.h"
#include "realdata/relations.h"
#include "rundir/csv_writer.h"
#include "rundir/layout.h"
#include "rundir/manifest.h"
#include "rundir/recording.h"
#include "rundir/rows.h"
#include "rundir/run_files.h"

namespace mjslam::app {
namespace {

using realdata::CarmenLog;
using realdata::LaserMessage;
using realdata::OdometryMessage;

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadToDeg = 180.0 / kPi;
// Laser poses this far from the odometry are an estimate of their own.
constexpr double kReferenceDistanceM = 0.05;
constexpr double kReferenceAngleRad = 0.05;

// The laser stream to import: the one asked for, or the first of the usual.
const std::vector<LaserMessage>& ChooseLaser(const CarmenLog& log, const std::string& asked) {
  if (!asked.empty()) {
    const auto it = log.lasers.find(asked);
    if (it == log.lasers.end() || it->second.empty()) {
      throw std::runtime_error(log.path + ": no " + asked + " messages (--laser " + asked + ")");
    }
    return it->second;
  }
  for (const char* kind : {"FLASER", "ROBOTLASER1", "RAWLASER1", "RLASER", "ROBOTLASER2",
                           "RAWLASER2", "RAWLASER3", "RAWLASER4", realdata::kBreezySlamLaser}) {
    const auto it = log.lasers.find(kind);
    if (it != log.lasers.end() && !it->second.empty()) return it->second;
  }
  throw std::runtime_error(log.path +
                           ": no laser messages (FLASER, RLASER, ROBOTLASERk, RAWLASERk)");
}

// Every scan must have the beam layout of the first: the config has one.
void CheckSameLayout(const CarmenLog& log, const std::vector<LaserMessage>& scans) {
  const LaserMessage& first = scans.front();
  for (const LaserMessage& scan : scans) {
    if (scan.ranges_m.size() != first.ranges_m.size() ||
        scan.angle_min_rad != first.angle_min_rad ||
        scan.angle_increment_rad != first.angle_increment_rad ||
        scan.max_range_m != first.max_range_m) {
      throw std::runtime_error(log.path + ":" + std::to_string(scan.line) + ": " + scan.kind +
                               ": beam layout differs from line " + std::to_string(first.line) +
                               " (" + std::to_string(scan.ranges_m.size()) + " beams vs " +
                               std::to_string(first.ranges_m.size()) + ")");
    }
  }
  if (first.ranges_m.size() < 2 || !(first.angle_increment_rad > 0.0) ||
      !(first.max_range_m > 0.0)) {
    throw std::runtime_error(log.path + ":" + std::to_string(first.line) + ": " + first.kind +
                             ": unusable beam layout (" + std::to_string(first.ranges_m.size()) +
                             " beams, step " + std::to_string(first.angle_increment_rad) +
                             " rad, max range " + std::to_string(first.max_range_m) + " m)");
  }
}

double LaserOffset(const CarmenLog& log, const ImportOptions& options, const std::string& kind) {
  if (std::isfinite(options.laser_offset_m)) return options.laser_offset_m;
  const bool rear = kind == "RLASER" || kind == "ROBOTLASER2" || kind == "RAWLASER2";
  const auto it = log.params.find(rear ? "robot_rearlaser_offset" : "robot_frontlaser_offset");
  if (it == log.params.end()) return 0.0;
  char* end = nullptr;
  const double value = std::strtod(it->second.c_str(), &end);
  if (*end != '\0' || !std::isfinite(value)) {
    throw std::runtime_error(log.path + ": PARAM " + it->first + ": expected a number (got '" +
                             it->second + "')");
  }
  return value;
}

// The odometry: the ODOM messages, or, in a log without them, the robot
// poses the laser messages carry.
std::vector<OdometryMessage> Odometry(const CarmenLog& log,
                                      const std::vector<LaserMessage>& scans) {
  if (!log.odometry.empty()) return log.odometry;
  if (!scans.front().has_poses) {
    throw std::runtime_error(log.path + ": no odometry: no ODOM messages, and " +
                             scans.front().kind + " carries no poses");
  }
  std::vector<OdometryMessage> odometry;
  for (const LaserMessage& scan : scans) {
    OdometryMessage odom;
    odom.t_s = scan.t_s;
    odom.pose = scan.robot_pose;
    odom.line = scan.line;
    odometry.push_back(odom);
  }
  return odometry;
}

// The odometry pose at `t_s` (within the stream's span): linear between the
// neighbouring messages, the heading along the shorter way.
Pose2 OdometryAt(const std::vector<OdometryMessage>& odometry, double t_s) {
  const auto later = std::lower_bound(
      odometry.begin(), odometry.end(), t_s,
      [](const OdometryMessage& m, double t) { return m.t_s < t; });
  if (later == odometry.end()) return odometry.back().pose;
  if (later->t_s == t_s || later == odometry.begin()) return later->pose;
  const OdometryMessage& a = *(later - 1);
  const OdometryMessage& b = *later;
  const double u = (t_s - a.t_s) / (b.t_s - a.t_s);
  return Pose2(a.pose.x + u * (b.pose.x - a.pose.x), a.pose.y + u * (b.pose.y - a.pose.y),
               a.pose.theta + u * WrapAngle(b.pose.theta - a.pose.theta));
}

// Whether the laser messages' robot poses are an estimate of their own.
bool PosesDifferFromOdometry(const std::vector<LaserMessage>& scans,
                             const std::vector<OdometryMessage>& odometry) {
  for (const LaserMessage& scan : scans) {
    const Pose2 odom =
        scan.has_odometry_at_scan ? scan.odometry_at_scan : OdometryAt(odometry, scan.t_s);
    if ((scan.robot_pose.translation() - odom.translation()).norm() > kReferenceDistanceM ||
        std::abs(WrapAngle(scan.robot_pose.theta - odom.theta)) > kReferenceAngleRad) {
      return true;
    }
  }
  return false;
}

bool HasReference(const ImportOptions& options, const std::vector<LaserMessage>& scans,
                  const std::vector<OdometryMessage>& odometry, bool log_has_odometry) {
  if (options.reference == "no") return false;
  if (!scans.front().has_poses) {
    if (options.reference == "yes") {
      throw std::runtime_error(options.log_path + ": --reference yes: " + scans.front().kind +
                               " carries no poses");
    }
    return false;
  }
  if (options.reference == "yes") return true;
  if (options.reference != "auto") {
    throw std::runtime_error("--reference: expected auto, yes or no (got '" + options.reference +
                             "')");
  }
  return log_has_odometry && PosesDifferFromOdometry(scans, odometry);
}

// The imported stream: what the run directory's files are written from.
struct Stream {
  std::vector<OdometryMessage> odometry;
  std::vector<const LaserMessage*> scans;  // within the odometry's span
  int scans_outside = 0;
  Pose2 X_BR;  // frame R on the robot centre B
  Pose2 X_BS;  // the laser on B
  Pose2 X_WO;  // the odometry frame in W
  bool has_reference = false;
};

// Ranges as the SLAM receives them: no return (<= 0, or at or past the
// maximum) at the maximum.
std::vector<double> SlamRanges(const LaserMessage& scan) {
  std::vector<double> ranges = scan.ranges_m;
  for (double& r : ranges) {
    if (!(r > 0.0) || r >= scan.max_range_m) r = scan.max_range_m;
  }
  return ranges;
}

// The log's timestamps must be at most this, seconds (UNIX time in the year
// 2286): a later one is a corrupt stamp.
constexpr double kMaxLogTimeS = 1e10;

// One row of trajectory.csv's recorded columns, and the log line it is from.
struct RecordedRow {
  double t_s = 0.0;
  Pose2 X_WR;
  double tv_mps = 0.0;
  double rv_radps = 0.0;
  int line = 0;
};

// Throws "LOG:LINE: ..." unless `value` is finite and within +-`limit`:
// what the run directory's readers would refuse later, naming their own
// file's line instead of the log's.
void CheckLogValue(const std::string& log_path, int line, const char* what, double value,
                   double limit) {
  if (std::isfinite(value) && std::abs(value) <= limit) return;
  char text[160];
  std::snprintf(text, sizeof(text), ": %s: expected a number in [-%g, %g] (got %g)", what, limit,
                limit, value);
  throw std::runtime_error(log_path + ":" + std::to_string(line) + text);
}

// trajectory.csv's recorded columns, one row per odometry message and per
// scan in time order, each checked against the readers' limits.
std::vector<RecordedRow> RecordedRows(const Stream& s, const std::string& log_path) {
  constexpr double kMax = rundir::kMaxRecordedCoordinateM;
  std::vector<RecordedRow> rows;
  std::size_t o = 0, k = 0;
  const OdometryMessage* last = &s.odometry.front();
  const double end = std::numeric_limits<double>::infinity();
  while (o < s.odometry.size() || k < s.scans.size()) {
    const double t_odom = o < s.odometry.size() ? s.odometry[o].t_s : end;
    const double t_scan = k < s.scans.size() ? s.scans[k]->t_s : end;
    const double t = std::min(t_odom, t_scan);
    if (t_odom == t) last = &s.odometry[o++];
    if (t_scan == t) ++k;
    const LaserMessage* scan = t_scan == t ? s.scans[k - 1] : nullptr;
    const Pose2 X_OB = scan != nullptr && scan->has_odometry_at_scan
                           ? scan->odometry_at_scan
                           : OdometryAt(s.odometry, t);
    RecordedRow row{t, s.X_WO * X_OB * s.X_BR, last->tv_mps, last->rv_radps,
                    scan != nullptr ? scan->line : last->line};
    CheckLogValue(log_path, row.line, "timestamp, s", t, kMaxLogTimeS);
    CheckLogValue(log_path, row.line, "odometry x, m", row.X_WR.x, kMax);
    CheckLogValue(log_path, row.line, "odometry y, m", row.X_WR.y, kMax);
    CheckLogValue(log_path, row.line, "odometry theta, rad", row.X_WR.theta, kMax);
    CheckLogValue(log_path, last->line, "translational velocity, m/s", row.tv_mps, kMax);
    CheckLogValue(log_path, last->line, "rotational velocity, rad/s", row.rv_radps, kMax);
    rows.push_back(row);
    if (rows.size() % 4096 == 0) ThrowIfInterrupted("import");
  }
  for (const LaserMessage* scan : s.scans) {
    CheckLogValue(log_path, scan->line, "maximum range, m", scan->max_range_m, kMax);
    if (!s.has_reference) continue;
    const Pose2 X_WR = scan->laser_pose * s.X_BS.Inverse() * s.X_BR;
    CheckLogValue(log_path, scan->line, "laser pose x, m", X_WR.x, kMax);
    CheckLogValue(log_path, scan->line, "laser pose y, m", X_WR.y, kMax);
    CheckLogValue(log_path, scan->line, "laser pose theta, rad", X_WR.theta, kMax);
  }
  return rows;
}

// scans.csv (no true laser pose), reference.csv and trajectory.csv's
// recorded columns (`rows`).
int WriteRecording(const Stream& s, const std::vector<RecordedRow>& rows, const std::string& dir) {
  const int num_beams = static_cast<int>(s.scans.front()->ranges_m.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  rundir::CsvWriter scans(rundir::PathIn(dir, rundir::kScansFile), rundir::ScanColumns(num_beams));
  std::unique_ptr<rundir::CsvWriter> reference;
  if (s.has_reference) {
    reference = std::make_unique<rundir::CsvWriter>(rundir::PathIn(dir, rundir::kReferenceFile),
                                                    rundir::ReferenceColumns());
  }
  for (const LaserMessage* scan : s.scans) {
    rundir::AddScanRow(scan->t_s, Pose2(nan, nan, nan), SlamRanges(*scan), &scans);
    if (!reference) continue;
    const Pose2 X_WR = scan->laser_pose * s.X_BS.Inverse() * s.X_BR;
    for (double value : {scan->t_s, X_WR.x, X_WR.y, X_WR.theta}) reference->Add(value);
    reference->EndRow();
  }
  rundir::CsvWriter trajectory(rundir::PathIn(dir, rundir::kTrajectoryFile),
                               rundir::RecordedTrajectoryColumns());
  for (const RecordedRow& row : rows) {
    for (double value : {row.t_s, nan, nan, nan, row.X_WR.x, row.X_WR.y, row.X_WR.theta,
                         row.tv_mps, row.rv_radps}) {
      trajectory.Add(value);
    }
    trajectory.EndRow();
  }
  scans.Flush();
  trajectory.Flush();
  if (reference) reference->Flush();
  return static_cast<int>(rows.size());
}

// The manifest of an imported run: the source, the layout, the counts, the
// reference and the relations' matching.
nlohmann::json ManifestFields(const ImportOptions& options, const ImportReport& report,
                              const LaserMessage& first, const Stream& s, bool log_reanchored) {
  nlohmann::json skipped = nlohmann::json::array();
  for (const std::string& line : report.skipped) skipped.push_back(line);
  return {{"mode", "import"},
          {"source_log", options.log_path},
          {"source_hash", rundir::HashFile(options.log_path)},
          {"laser_message", first.kind},
          {"num_beams", report.num_beams},
          {"angle_min_deg", first.angle_min_rad * kRadToDeg},
          {"angle_step_deg", first.angle_increment_rad * kRadToDeg},
          {"max_range_m", first.max_range_m},
          {"laser_offset_m", s.X_BS.x},
          {"num_scans", report.num_scans},
          {"num_odometry", report.num_odometry},
          {"odometry", !log_reanchored ? "as logged"
                       : report.odometry_rebuilt
                           ? "rebuilt from the logged increments (the log restarts its ODOM "
                             "lines at each scan's corrected pose)"
                           : "as logged (restarted at each scan's corrected pose)"},
          {"skipped", skipped},
          {"warnings", report.warnings},
          {"reference", s.has_reference ? "reference.csv: the log's own pose estimate (a SLAM "
                                          "result, not ground truth)"
                                        : "none"},
          {"relations_file", options.relations_path},
          {"relations_time_offset_s", report.time_offset_s},
          {"relations_tolerance_s", options.tolerance_s},
          {"mjslam_version", MjslamVersion()},
          {"git_commit", MjslamGitCommit()},
          {"config_file", options.config_path},
          {"command_line", options.command_line}};
}

// The log in the reader's common form, read by its format.
CarmenLog ReadLog(const ImportOptions& options) {
  const std::string& format = options.format;
  if (format != "auto" && format != "carmen" && format != "breezyslam") {
    throw std::runtime_error("--format: expected auto, carmen or breezyslam (got '" + format + "')");
  }
  realdata::RequireRegularFile(options.log_path);
  realdata::BreezySlamOptions breezyslam = options.breezyslam;
  if (options.read.max_range_m > 0.0) breezyslam.max_range_m = options.read.max_range_m;
  if (format == "breezyslam" ||
      (format == "auto" && realdata::LooksLikeBreezySlamLog(options.log_path, breezyslam))) {
    return realdata::ReadBreezySlamLog(options.log_path, breezyslam);
  }
  return realdata::ReadCarmenLog(options.log_path, options.read);
}

}  // namespace

// Reads the log, sets the config's laser from it, writes the recording and
// the manifest, then replays the recording into the same directory.
ImportReport ImportLog(RunConfig config, const ImportOptions& options) {
  CheckImportOptions(options);
  const CarmenLog log = ReadLog(options);
  const std::vector<LaserMessage>& all_scans = ChooseLaser(log, options.laser);
  CheckSameLayout(log, all_scans);
  const LaserMessage& first = all_scans.front();
  const int num_beams = static_cast<int>(first.ranges_m.size());
  config.laser.num_beams = num_beams;
  config.laser.fov_deg = (num_beams - 1) * first.angle_increment_rad * kRadToDeg;
  config.laser.max_range_m = first.max_range_m;
  config.ValidateOrThrow();

  Stream s;
  s.odometry = Odometry(log, all_scans);
  for (const LaserMessage& scan : all_scans) {
    const bool inside =
        scan.t_s >= s.odometry.front().t_s && scan.t_s <= s.odometry.back().t_s;
    if (inside) s.scans.push_back(&scan);
    s.scans_outside += inside ? 0 : 1;
  }
  if (s.scans.empty()) throw std::runtime_error(log.path + ": no scan within the odometry's time span");
  const double a = config.slam.ekf.control_point_offset_m;
  s.X_BR = Pose2(a, 0.0, 0.0);
  // The fan is centred on the x axis of S (config.laser); its own offset
  // from the log's beam 0 is a turn of S.
  const double fan_turn = first.angle_min_rad + 0.5 * config.laser.fov_deg / kRadToDeg;
  s.X_BS = Pose2(LaserOffset(log, options, first.kind), 0.0, fan_turn);
  s.has_reference = HasReference(options, all_scans, s.odometry, !log.odometry.empty());
  const double t0 = s.scans.front()->t_s;
  if (s.has_reference) {
    const Pose2 X_WB0 = s.scans.front()->laser_pose * s.X_BS.Inverse();
    const LaserMessage& scan0 = *s.scans.front();
    s.X_WO = X_WB0 * (scan0.has_odometry_at_scan ? scan0.odometry_at_scan
                                                  : OdometryAt(s.odometry, t0))
                         .Inverse();
  }

  ImportReport report;
  report.laser = first.kind;
  report.num_beams = num_beams;
  report.num_scans = static_cast<int>(s.scans.size());
  report.num_odometry = static_cast<int>(s.odometry.size());
  report.has_reference = s.has_reference;
  report.odometry_rebuilt = log.reanchored && !options.read.odometry_as_logged;
  report.skipped = realdata::SkipReport(log);
  report.warnings = log.warnings;
  if (s.scans_outside > 0) {
    report.skipped.push_back(first.kind + ": outside the odometry's time span: " +
                             std::to_string(s.scans_outside) + " scans");
  }
  report.time_offset_s = options.time_offset_s;
  if (!options.relations_path.empty() && !std::isfinite(report.time_offset_s)) {
    std::vector<realdata::TimedPose> scan_times;
    for (const LaserMessage* scan : s.scans) scan_times.push_back({scan->t_s, Pose2()});
    try {
      report.time_offset_s =
          realdata::BestTimeOffset(realdata::ReadRelations(options.relations_path), scan_times,
                                   options.tolerance_s, nullptr, options.max_offset_candidates);
    } catch (const std::length_error& error) {
      throw std::runtime_error("--relations " + options.relations_path + ": " + error.what() +
                               " (--max-offset-candidates " +
                               std::to_string(options.max_offset_candidates) +
                               "): give the offset with --time-offset");
    }
  }
  // Every value checked before anything is written.
  const std::vector<RecordedRow> rows = RecordedRows(s, log.path);
  if (options.check_only) return report;

  const std::string& dir = options.out_dir;
  const rundir::RunDirectoryLock lock(dir);
  rundir::WriteFileAtomically(rundir::PathIn(dir, rundir::kConfigFile), config::ToYaml(config));
  rundir::ManifestWriter manifest(dir, ManifestFields(options, report, first, s, log.reanchored));
  manifest.SetLaserMount(s.X_BR.Inverse() * s.X_BS);
  manifest.Write();
  try {
    report.num_steps = WriteRecording(s, rows, dir);
    ThrowIfInterrupted("import");
  } catch (const Interrupted&) {
    manifest.Finish("interrupted");
    throw;
  } catch (const std::exception& error) {
    manifest.Fail(error.what());
    throw;
  }
  const rundir::Recording recording(rundir::PathIn(dir, rundir::kScansFile), "", num_beams);
  report.interrupted = !ReplayRecording(config, recording, dir, &manifest);
  return report;
}

void CheckImportOptions(const ImportOptions& o) {
  auto refuse = [](const std::string& option, double value, const std::string& expected) {
    throw std::runtime_error(option + ": expected " + expected + " (got " + ValueText(value) + ")");
  };
  const auto& r = o.read;
  if (!(std::abs(r.angle_min_deg) <= 360.0)) refuse("--angle-min-deg", r.angle_min_deg, "degrees in [-360, 360]");
  if (!(r.angle_step_deg >= 0.0 && r.angle_step_deg <= 360.0)) {
    refuse("--angle-step-deg", r.angle_step_deg, "degrees in [0, 360] (0: from the beam count)");
  }
  if (!(r.max_range_m >= 0.0 && r.max_range_m <= rundir::kMaxRecordedCoordinateM)) {
    refuse("--max-range", r.max_range_m, "metres in [0, 1e6] (0: from the log)");
  }
  if (!std::isnan(o.laser_offset_m) && !(std::abs(o.laser_offset_m) <= 100.0)) {
    refuse("--laser-offset", o.laser_offset_m, "metres in [-100, 100]");
  }
  if (!std::isnan(o.time_offset_s) && !std::isfinite(o.time_offset_s)) {
    refuse("--time-offset", o.time_offset_s, "a finite number of seconds, or auto");
  }
  if (!(o.tolerance_s > 0.0 && o.tolerance_s <= 10.0)) {
    refuse("--tolerance", o.tolerance_s, "seconds in (0, 10]");
  }
}

}  // namespace mjslam::app
