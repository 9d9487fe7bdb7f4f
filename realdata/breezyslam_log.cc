#include "realdata/breezyslam_log.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "common/interrupt.h"

namespace mjslam::realdata {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;
// Fields before the ranges: timestamp, ?, left ticks, right ticks, 20 unused.
constexpr int kFieldsBeforeRanges = 24;
constexpr int kLeftTicksField = 2;
constexpr int kRightTicksField = 3;

// The integer of field `i`, or an error naming the field.
long long Integer(const std::vector<std::string>& tokens, int i) {
  const std::string& text = tokens[i];
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (end == text.c_str() || *end != '\0') {
    throw std::runtime_error("field " + std::to_string(i) + ": expected an integer (got '" +
                             Shown(text) + "')");
  }
  return value;
}

void CheckOptions(const std::string& path, const BreezySlamOptions& o) {
  if (!(o.wheel_radius_m > 0.0) || !(o.half_axle_m > 0.0) || o.ticks_per_revolution <= 0 ||
      o.num_beams < 2 || !(o.fov_deg > 0.0) || !(o.max_range_m > 0.0) || o.margin_beams < 0 ||
      2 * o.margin_beams + 2 > o.num_beams) {
    throw std::runtime_error(path + ": unusable BreezySLAM rover or laser parameters");
  }
}

}  // namespace

int BreezySlamFieldsPerLine(int num_beams) { return kFieldsBeforeRanges + num_beams + 1; }

CarmenLog ReadBreezySlamLog(const std::string& path, const BreezySlamOptions& options) {
  CheckOptions(path, options);
  RequireRegularFile(path);
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  CarmenLog log;
  log.path = path;
  char offset[32];
  const std::to_chars_result written =
      std::to_chars(offset, offset + sizeof(offset), options.laser_offset_m);  // shortest exact
  log.params["robot_frontlaser_offset"] = std::string(offset, written.ptr);
  std::vector<LaserMessage>& scans = log.lasers[kBreezySlamLaser];
  const int fields = BreezySlamFieldsPerLine(options.num_beams);
  const double radians_per_tick = 2.0 * kPi / options.ticks_per_revolution;
  Pose2 pose;
  long long last_left = 0, last_right = 0;
  std::string line;
  while (std::getline(in, line)) {
    const int line_number = ++log.num_lines;
    if (line_number % 1024 == 0) ThrowIfInterrupted("reading the log");
    const std::string where = path + ":" + std::to_string(line_number) + ": ";
    if (line.size() > kMaxLogLineBytes) {
      throw std::runtime_error(where + "line longer than " + std::to_string(kMaxLogLineBytes) +
                               " bytes (not a log?)");
    }
    const std::vector<std::string> tokens = SplitLogFields(line);
    if (tokens.empty()) continue;
    if (static_cast<int>(tokens.size()) != fields) {
      throw std::runtime_error(where + "expected " + std::to_string(fields) + " fields for " +
                               std::to_string(options.num_beams) + " beams (got " +
                               std::to_string(tokens.size()) + "; truncated line?)");
    }
    OdometryMessage odom;
    LaserMessage scan;
    try {
      odom.t_s = static_cast<double>(Integer(tokens, 0)) * 1e-6;
      const long long left = Integer(tokens, kLeftTicksField);
      const long long right = Integer(tokens, kRightTicksField);
      if (!log.odometry.empty()) {
        const double phi_left = static_cast<double>(left - last_left) * radians_per_tick;
        const double phi_right = static_cast<double>(right - last_right) * radians_per_tick;
        const double distance = options.wheel_radius_m * 0.5 * (phi_left + phi_right);
        const double turn = options.wheel_radius_m * (phi_right - phi_left) / (2.0 * options.half_axle_m);
        const double heading = pose.theta + 0.5 * turn;
        pose = Pose2(pose.x + distance * std::cos(heading), pose.y + distance * std::sin(heading),
                     pose.theta + turn);
      }
      last_left = left;
      last_right = right;
      scan.ranges_m.resize(options.num_beams);
      for (int b = 0; b < options.num_beams; ++b) {
        const long long mm = Integer(tokens, kFieldsBeforeRanges + b);
        const bool margin = b <= options.margin_beams || b >= options.num_beams - options.margin_beams;
        scan.ranges_m[b] = margin ? 0.0 : static_cast<double>(mm) * 1e-3;
      }
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(where + e.what());
    }
    if (!log.odometry.empty() && !(odom.t_s > log.odometry.back().t_s)) {
      throw std::runtime_error(where + "timestamp " + Shown(tokens[0]) +
                               " us not after the line before's");
    }
    odom.pose = pose;
    odom.line = line_number;
    scan.kind = kBreezySlamLaser;
    scan.t_s = odom.t_s;
    scan.angle_min_rad = -0.5 * options.fov_deg * kDegToRad;
    scan.angle_increment_rad = options.fov_deg / (options.num_beams - 1) * kDegToRad;
    scan.max_range_m = options.max_range_m;
    scan.has_odometry_at_scan = true;
    scan.odometry_at_scan = pose;
    scan.line = line_number;
    log.odometry.push_back(odom);
    scans.push_back(std::move(scan));
  }
  if (scans.empty()) throw std::runtime_error(path + ": no BreezySLAM log line");
  return log;
}

bool LooksLikeBreezySlamLog(const std::string& path, const BreezySlamOptions& options) {
  RequireRegularFile(path);
  std::ifstream in(path);
  std::string line;
  if (!in || !std::getline(in, line)) return false;
  const std::vector<std::string> tokens = SplitLogFields(line);
  if (static_cast<int>(tokens.size()) != BreezySlamFieldsPerLine(options.num_beams)) return false;
  try {
    for (int i : {0, kLeftTicksField, kRightTicksField}) Integer(tokens, i);
    for (int b = 0; b < options.num_beams; ++b) Integer(tokens, kFieldsBeforeRanges + b);
  } catch (const std::runtime_error&) {
    return false;
  }
  return true;
}

}  // namespace mjslam::realdata
