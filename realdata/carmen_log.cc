#include "realdata/carmen_log.h"

#include <sys/stat.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "common/interrupt.h"

namespace mjslam::realdata {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;
// The range a SICK LMS reports without an echo (8183 cm): CARMEN's FLASER
// maximum when the log names none.
constexpr double kSickNoReturnM = 81.83;
// The first malformed lines kept verbatim in CarmenLog::bad_lines.
constexpr std::size_t kMaxBadLinesKept = 5;
// Skip reasons kept apart; the lines of further unknown message names are
// counted together (a garbage file must not make an unbounded report).
constexpr std::size_t kMaxSkipReasons = 40;
// A message stamped this far ahead of the next one of its stream, which
// follows the one before it, is a corrupt stamp (Keep).
constexpr double kCorruptLeadS = 3600.0;
// Lines read between two looks at a stop request.
constexpr int kLinesPerInterruptCheck = 1024;

// A malformed line: its message, without the file and line.
struct BadLine : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Reads the lines of a plain or gzip file (zlib passes plain files through).
class LineReader {
 public:
  explicit LineReader(const std::string& path) : file_(nullptr, gzclose), path_(path) {
    RequireRegularFile(path);
    file_.reset(gzopen(path.c_str(), "rb"));
    if (!file_) throw std::runtime_error(path + ": cannot open");
  }
  // The next line, without its line end; false at the end of the file. A
  // line longer than kMaxLogLineBytes is read to its end and returned empty
  // with *too_long set.
  bool Next(std::string* line, bool* too_long) {
    line->clear();
    *too_long = false;
    if (++lines_ % kLinesPerInterruptCheck == 0) ThrowIfInterrupted("reading the log");
    char buffer[1 << 16];
    while (gzgets(file_.get(), buffer, sizeof(buffer)) != nullptr) {
      line->append(buffer);
      const bool ends = !line->empty() && line->back() == '\n';
      if (line->size() > kMaxLogLineBytes) {
        *too_long = true;
        line->clear();
        if (ends) return true;
        ThrowIfInterrupted("reading the log");
        continue;
      }
      if (ends) {
        line->pop_back();
        if (!line->empty() && line->back() == '\r') line->pop_back();
        return true;
      }
    }
    // zlib's Z_BUF_ERROR here is a gzip stream cut short: an error too.
    int error = Z_OK;
    const char* message = gzerror(file_.get(), &error);
    if (error != Z_OK) throw std::runtime_error(path_ + ": cannot read: " + message);
    return !line->empty() || *too_long;  // a last line without a line end
  }

 private:
  std::unique_ptr<gzFile_s, int (*)(gzFile)> file_;
  std::string path_;
  long long lines_ = 0;
};

// Reads the message fields of one line, each checked.
class Fields {
 public:
  explicit Fields(std::vector<std::string> tokens) : tokens_(std::move(tokens)) {}
  std::size_t size() const { return tokens_.size(); }
  double Number(std::size_t i) const {
    if (i >= tokens_.size()) {
      throw BadLine(Shown(tokens_[0]) + ": field " + std::to_string(i) +
                    " missing (truncated line?)");
    }
    const std::string& text = tokens_[i];
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0' || !std::isfinite(value)) {
      throw BadLine(Shown(tokens_[0]) + ": field " + std::to_string(i) +
                    ": expected a number (got '" + Shown(text) + "')");
    }
    return value;
  }
  int Count(std::size_t i) const {
    const double value = Number(i);
    if (value < 0 || value > 100000 || value != std::floor(value)) {
      throw BadLine(Shown(tokens_[0]) + ": field " + std::to_string(i) +
                    ": expected a count (got '" + Shown(tokens_[i]) + "')");
    }
    return static_cast<int>(value);
  }
  void ExpectSize(std::size_t expected, const std::string& what) const {
    if (tokens_.size() != expected) {
      throw BadLine(Shown(tokens_[0]) + ": expected " + std::to_string(expected) + " fields " + what +
                    " (got " + std::to_string(tokens_.size()) + "; truncated line?)");
    }
  }
  Pose2 PoseAt(std::size_t i) const { return Pose2(Number(i), Number(i + 1), Number(i + 2)); }
  std::vector<double> Ranges(std::size_t first, int n) const {
    std::vector<double> ranges(n);
    for (int b = 0; b < n; ++b) ranges[b] = Number(first + b);
    return ranges;
  }
  // The ipc timestamp: third field from the end (timestamp hostname logger).
  double IpcTimestamp() const { return Number(tokens_.size() - 3); }

 private:
  std::vector<std::string> tokens_;
};

OdometryMessage ParseOdom(const Fields& f) {
  f.ExpectSize(10, "(ODOM x y theta tv rv accel timestamp host logger_timestamp)");
  OdometryMessage odom;
  odom.pose = f.PoseAt(1);
  odom.tv_mps = f.Number(4);
  odom.rv_radps = f.Number(5);
  odom.t_s = f.IpcTimestamp();
  return odom;
}

// FLASER/RLASER n r_1..r_n x y theta odom_x odom_y odom_theta timestamp host logger.
LaserMessage ParseOldLaser(const Fields& f, const CarmenReadOptions& options, double max_range_m) {
  const int n = f.Count(1);
  f.ExpectSize(2 + n + 9, "for " + std::to_string(n) + " beams");
  LaserMessage laser;
  laser.ranges_m = f.Ranges(2, n);
  laser.angle_min_rad = options.angle_min_deg * kDegToRad;
  laser.angle_increment_rad =
      (options.angle_step_deg > 0.0 ? options.angle_step_deg : CarmenDefaultStepDeg(n)) *
      kDegToRad;
  laser.max_range_m = max_range_m;
  laser.has_poses = true;
  laser.laser_pose = f.PoseAt(2 + n);
  laser.robot_pose = f.PoseAt(5 + n);
  laser.t_s = f.IpcTimestamp();
  return laser;
}

// RAWLASERk / ROBOTLASERk: type start_angle fov resolution max_range accuracy
// remission_mode n r_1..r_n n_rem rem_1..rem_m, then (ROBOTLASER) laser pose,
// robot pose, tv rv forward_safety side_safety turn_axis; timestamp host logger.
LaserMessage ParseNewLaser(const Fields& f, bool robot, double max_range_override_m) {
  const int n = f.Count(8);
  const int num_remissions = f.Count(9 + n);
  const std::size_t tail = robot ? 11 : 0;
  f.ExpectSize(10 + n + num_remissions + tail + 3,
               "for " + std::to_string(n) + " beams and " + std::to_string(num_remissions) +
                   " remissions");
  LaserMessage laser;
  laser.angle_min_rad = f.Number(2);
  laser.angle_increment_rad = f.Number(4);
  laser.max_range_m = max_range_override_m > 0.0 ? max_range_override_m : f.Number(5);
  laser.ranges_m = f.Ranges(9, n);
  if (robot) {
    const std::size_t poses = 10 + n + num_remissions;
    laser.has_poses = true;
    laser.laser_pose = f.PoseAt(poses);
    laser.robot_pose = f.PoseAt(poses + 3);
  }
  laser.t_s = f.IpcTimestamp();
  return laser;
}

bool IsNewLaser(const std::string& kind, const char* prefix) {
  const std::string p(prefix);
  return kind.size() == p.size() + 1 && kind.compare(0, p.size(), p) == 0 &&
         kind.back() >= '1' && kind.back() <= '4';
}

// The maximum range of FLASER/RLASER: the user's, the log's PARAM, or SICK's.
double OldLaserMaxRange(const CarmenLog& log, const CarmenReadOptions& options) {
  if (options.max_range_m > 0.0) return options.max_range_m;
  const auto it = log.params.find("robot_front_laser_max");
  if (it != log.params.end()) {
    char* end = nullptr;
    const double value = std::strtod(it->second.c_str(), &end);
    if (*end == '\0' && value > 0.0) return value;
  }
  return kSickNoReturnM;
}

// Whether two logged poses are the same numbers (as printed, to the last
// digit): the corrected logs' ODOM copy of a scan's pose.
bool SamePose(const Pose2& a, const Pose2& b) {
  constexpr double kPrinted = 1e-9;
  return std::abs(a.x - b.x) <= kPrinted && std::abs(a.y - b.y) <= kPrinted &&
         std::abs(WrapAngle(a.theta - b.theta)) <= kPrinted;
}

// The odometry of a log whose ODOM lines restart from each scan's corrected
// pose (CarmenLog::reanchored): the pose of each ODOM line, rebuilt by
// chaining the logged increments (each from the line before, or from the
// scan's pose at the start of a segment) in log order.
class OdometryChain {
 public:
  // The pose to keep for an ODOM line logged at `logged`: `logged` itself,
  // or, when `rebuild`, the chain's pose.
  Pose2 Next(const Pose2& logged, bool rebuild) {
    rebuilt_ = rebuild && started_ ? rebuilt_ * (anchor_.Inverse() * logged) : logged;
    anchor_ = logged;
    started_ = true;
    return rebuilt_;
  }
  // A segment starts: the next increment is measured from `logged`, which is
  // where the odometry is now.
  void Reanchor(const Pose2& logged) {
    anchor_ = logged;
    started_ = true;
  }

 private:
  Pose2 anchor_;
  Pose2 rebuilt_;
  bool started_ = false;
};

// Counts a skipped line under `reason`; past kMaxSkipReasons reasons, under
// one shared reason.
void CountSkip(const std::string& reason, CarmenLog* log) {
  const bool known = log->skipped.count(reason) > 0 || log->skipped.size() < kMaxSkipReasons;
  ++log->skipped[known ? reason : "other lines: not read"];
}

// Keeps a message whose timestamp is positive and not before the last one
// kept (equal ones are spread afterwards: SpreadTies). A message before the
// last one kept but not before the one kept ahead of it shows the last one
// kept, and more than kCorruptLeadS after it, shows the last one kept to be
// a corrupt stamp in the future: that one is dropped instead (else it would
// drop the rest of the stream), and reported. (The corrected logs' clock
// steps back by up to a second: those messages are skipped, as before.)
template <typename Message>
void Keep(Message message, const std::string& kind, std::vector<Message>* stream, CarmenLog* log) {
  const std::size_t n = stream->size();
  if (message.t_s <= 0.0) {
    ++log->skipped[kind + ": timestamp <= 0"];
  } else if (n > 0 && message.t_s < stream->back().t_s) {
    if (n >= 2 && message.t_s >= (*stream)[n - 2].t_s &&
        stream->back().t_s - message.t_s > kCorruptLeadS) {
      const Message& future = stream->back();
      ++log->skipped[kind + ": timestamp later than the next message's (corrupt?)"];
      if (log->bad_lines.size() < kMaxBadLinesKept) {
        char stamps[96];
        std::snprintf(stamps, sizeof(stamps), "timestamp %.9g s, the next %s at line %d has %.9g s",
                      future.t_s, kind.c_str(), message.line, message.t_s);
        log->bad_lines.push_back(log->path + ":" + std::to_string(future.line) + ": " + kind +
                                 ": " + stamps);
      }
      stream->back() = std::move(message);
    } else {
      ++log->skipped[kind + ": timestamp before the previous one"];
    }
  } else {
    stream->push_back(std::move(message));
  }
}

// Gives the messages of `stream` that share a timestamp increasing times in
// line order (ReadCarmenLog documents how) and warns how many there were.
template <typename Message>
void SpreadTies(const std::string& kind, std::vector<Message>* stream, CarmenLog* log) {
  const std::size_t n = stream->size();
  std::size_t tied = 0;
  for (std::size_t i = 1; i < n; ++i) tied += (*stream)[i].t_s == (*stream)[i - 1].t_s;
  if (tied == 0) return;
  // The mean step, for the last run (which has no next stamp).
  const double span = stream->back().t_s - stream->front().t_s;
  const double mean_step = n - tied > 1 ? span / static_cast<double>(n - tied - 1) : 1.0;
  for (std::size_t begin = 0; begin < n;) {
    std::size_t end = begin + 1;
    while (end < n && (*stream)[end].t_s == (*stream)[begin].t_s) ++end;
    const double t = (*stream)[begin].t_s;
    const double next = end < n ? (*stream)[end].t_s : t + mean_step;
    const double k = static_cast<double>(end - begin);
    for (std::size_t i = begin + 1; i < end; ++i) {
      (*stream)[i].t_s = t + static_cast<double>(i - begin) * (next - t) / k;
    }
    begin = end;
  }
  log->warnings.push_back(kind + ": " + std::to_string(tied) + " of " + std::to_string(n) +
                          " messages share their timestamp with the one before (timestamps of "
                          "low precision, or a clock that stalls): their times are spread in "
                          "line order between the neighbouring stamps");
}

}  // namespace

void RequireRegularFile(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) throw std::runtime_error(path + ": cannot open");
  if (!S_ISREG(info.st_mode)) {
    throw std::runtime_error(path + ": not a regular file (a pipe, FIFO or device is read "
                             "once and may never end): save it to a file first");
  }
}

std::string Shown(const std::string& text) {
  constexpr std::size_t kShown = 60;
  if (text.size() <= kShown) return text;
  return text.substr(0, kShown) + "... (" + std::to_string(text.size()) + " bytes)";
}

double CarmenDefaultStepDeg(int num_beams) {
  if (num_beams == 180 || num_beams == 181) return 1.0;
  if (num_beams == 360 || num_beams == 361) return 0.5;
  if (num_beams == 720 || num_beams == 721) return 0.25;
  return num_beams > 1 ? 180.0 / (num_beams - 1) : 180.0;
}

CarmenLog ReadCarmenLog(const std::string& path, const CarmenReadOptions& options) {
  CarmenLog log;
  log.path = path;
  LineReader reader(path);
  std::string line;
  // The last ODOM message read, kept or not, and whether it is the message
  // just before the current line.
  OdometryMessage last_odom;
  bool odom_just_before = false;
  // The laser message of the line before, when it carries poses: an ODOM
  // line repeating its robot pose re-anchors the odometry.
  LaserMessage laser_seen;
  const LaserMessage* laser_just_before = nullptr;
  OdometryChain chain;
  bool too_long = false;
  while (reader.Next(&line, &too_long)) {
    const int line_number = ++log.num_lines;
    if (too_long) line = "LINE_TOO_LONG";
    std::vector<std::string> tokens = SplitLogFields(line);
    if (tokens.empty() || tokens[0][0] == '#') continue;
    const std::string kind = tokens[0];
    Fields fields(std::move(tokens));
    try {
      if (too_long) {
        throw BadLine("line longer than " + std::to_string(kMaxLogLineBytes) +
                      " bytes (not a log?)");
      } else if (kind == "PARAM") {
        if (fields.size() < 3) throw BadLine("PARAM: expected a name and a value");
        std::vector<std::string> pair = SplitLogFields(line);
        log.params[pair[1]] = pair[2];
      } else if (kind == "ODOM") {
        OdometryMessage odom = ParseOdom(fields);
        odom.line = line_number;
        if (laser_just_before != nullptr && SamePose(odom.pose, laser_just_before->robot_pose)) {
          log.reanchored = true;
          chain.Reanchor(odom.pose);
          ++log.skipped["ODOM: the scan's corrected pose (restarts the logged odometry)"];
          laser_just_before = nullptr;
          odom_just_before = false;
          continue;
        }
        odom.pose = chain.Next(odom.pose, log.reanchored && !options.odometry_as_logged);
        Keep(odom, kind, &log.odometry, &log);
        last_odom = odom;
        odom_just_before = true;
        laser_just_before = nullptr;
        continue;
      } else if (kind == "FLASER" || kind == "RLASER" || IsNewLaser(kind, "RAWLASER") ||
                 IsNewLaser(kind, "ROBOTLASER")) {
        LaserMessage laser =
            kind == "FLASER" || kind == "RLASER"
                ? ParseOldLaser(fields, options, OldLaserMaxRange(log, options))
                : ParseNewLaser(fields, kind[1] == 'O', options.max_range_m);
        laser.kind = kind;
        laser.line = line_number;
        laser.has_odometry_at_scan = odom_just_before && last_odom.t_s == laser.t_s;
        laser.odometry_at_scan = last_odom.pose;
        laser_seen = laser;
        Keep(laser, kind, &log.lasers[kind], &log);
        odom_just_before = false;
        laser_just_before = laser_seen.has_poses ? &laser_seen : nullptr;
        continue;
      } else {
        CountSkip(Shown(kind) + ": not read", &log);
      }
      odom_just_before = false;
      laser_just_before = nullptr;
    } catch (const BadLine& bad) {
      const std::string message = path + ":" + std::to_string(line_number) + ": " + bad.what();
      if (!options.skip_bad_lines) throw std::runtime_error(message);
      odom_just_before = false;
      laser_just_before = nullptr;
      ++log.skipped["bad line"];
      if (log.bad_lines.size() < kMaxBadLinesKept) log.bad_lines.push_back(message);
    }
  }
  SpreadTies("ODOM", &log.odometry, &log);
  for (auto& [kind, stream] : log.lasers) SpreadTies(kind, &stream, &log);
  return log;
}

std::vector<std::string> SplitLogFields(const std::string& line) {
  std::vector<std::string> tokens;
  std::istringstream in(line);
  std::string token;
  while (in >> token) tokens.push_back(token);
  return tokens;
}

std::vector<std::string> SkipReport(const CarmenLog& log) {
  std::vector<std::string> report;
  for (const auto& [reason, count] : log.skipped) {
    report.push_back(reason + ": " + std::to_string(count) + (count == 1 ? " line" : " lines"));
  }
  for (const std::string& bad : log.bad_lines) report.push_back("  " + bad);
  return report;
}

}  // namespace mjslam::realdata
