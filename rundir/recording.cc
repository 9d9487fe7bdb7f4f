#include "rundir/recording.h"

#include <filesystem>
#include <limits>
#include <optional>
#include <stdexcept>

#include "rundir/layout.h"
#include "rundir/manifest.h"
#include "rundir/rows.h"

namespace mjslam::rundir {
namespace {

// The pose in columns col, col + 1, col + 2 of `row`, as written.
Pose2 RawPose(const std::vector<double>& row, int col) {
  Pose2 pose;
  pose.x = row[col];
  pose.y = row[col + 1];
  pose.theta = row[col + 2];
  return pose;
}

// Columns of the recorded trajectory (checked to come first, in this order).
constexpr int kTimeColumn = 0;
constexpr int kTrueColumn = 1;
constexpr int kOdometryColumn = 4;
constexpr int kCommandColumn = 7;

}  // namespace

Recording::Recording(const std::string& scans_path, const std::string& trajectory_path,
                     int num_beams) {
  const std::filesystem::path scans_dir = std::filesystem::path(scans_path).parent_path();
  const std::string trajectory_file =
      trajectory_path.empty() ? (scans_dir / kTrajectoryFile).string() : trajectory_path;
  scans_ = ReadScansCsv(scans_path);
  trajectory_ = ReadTrajectoryCsv(trajectory_file);
  if (scans_.rows.empty()) throw std::runtime_error(scans_path + ": no rows (no scans to replay)");

  // Columns of the inputs.
  if (static_cast<int>(scans_.columns.size()) != kScanRangesStart + num_beams) {
    throw std::runtime_error(scans_path + ": expected " + std::to_string(kScanRangesStart + num_beams) +
                             " columns for laser.num_beams = " + std::to_string(num_beams) +
                             " (got " + std::to_string(scans_.columns.size()) + ")");
  }
  // The explored fraction is the run's (it needs the world), when it has one.
  for (std::size_t c = 0; c < trajectory_.columns.size(); ++c) {
    if (trajectory_.columns[c] == "explored") explored_column_ = static_cast<int>(c);
  }
  for (const std::vector<double>& row : scans_.rows) {
    ranges_at_[row[0]].assign(row.begin() + kScanRangesStart, row.end());
  }

  const std::optional<Pose2> mount = ReadLaserMount((scans_dir / kManifestFile).string());
  if (mount) {
    X_RS_ = *mount;
    return;
  }
  // The mount from the true poses of R and of the laser at the first scan.
  auto pose_at = [](const std::vector<double>& row, int col) {
    return Pose2(row[col], row[col + 1], row[col + 2]);
  };
  std::map<double, const std::vector<double>*> scan_at;
  for (const std::vector<double>& row : scans_.rows) scan_at[row[0]] = &row;
  for (const std::vector<double>& row : trajectory_.rows) {
    auto it = scan_at.find(row[kTimeColumn]);
    if (it == scan_at.end()) continue;
    X_RS_ = pose_at(row, kTrueColumn).Inverse() * pose_at(*it->second, 1);
    return;
  }
  throw std::runtime_error(scans_path + ": no scan at a trajectory time");
}

RecordedStep Recording::Step(std::size_t i) const {
  const std::vector<double>& row = trajectory_.rows[i];
  RecordedStep step;
  step.t_s = row[kTimeColumn];
  step.X_WR_true = RawPose(row, kTrueColumn);
  step.X_WR_odometry = RawPose(row, kOdometryColumn);
  step.command = {row[kCommandColumn], row[kCommandColumn + 1]};
  step.explored = explored_column_ >= 0 ? row[explored_column_]
                                        : std::numeric_limits<double>::quiet_NaN();
  const auto it = ranges_at_.find(step.t_s);
  if (it != ranges_at_.end()) step.scan_ranges_m = &it->second;
  return step;
}

}  // namespace mjslam::rundir
