#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "common/pose2.h"
#include "common/records.h"
#include "rundir/csv_reader.h"

namespace mjslam::rundir {

/// One recorded control step of an earlier run, as trajectory.csv and
/// scans.csv hold it (values as written, angles not re-wrapped).
struct RecordedStep {
  double t_s = 0.0;
  Pose2 X_WR_true;
  Pose2 X_WR_odometry;
  /// The command applied from t_s to the next step.
  Twist2 command;
  /// The explored fraction; NaN when the recording has none.
  double explored = 0.0;
  /// The ranges of the scan taken at t_s, metres; null when none was.
  const std::vector<double>* scan_ranges_m = nullptr;
};

/// The scans and trajectory of an earlier run, what `mjslam replay` reads.
class Recording {
 public:
  /// Reads `scans_path` (scans.csv, `num_beams` ranges per row) and
  /// `trajectory_path` (empty: the trajectory.csv beside the scans), whose
  /// recorded columns t .. cmd_w must come first in the order of a run. The
  /// laser mount comes from the manifest.json beside the scans when it has
  /// one, else from the true poses of R and of the laser at the first scan.
  /// Throws std::runtime_error naming the file (and column) of bad input.
  Recording(const std::string& scans_path, const std::string& trajectory_path, int num_beams);

  /// The files read.
  const std::string& scans_path() const { return scans_.path; }
  const std::string& trajectory_path() const { return trajectory_.path; }
  /// Number of recorded steps (at least one).
  std::size_t num_steps() const { return trajectory_.rows.size(); }
  /// Step `i` < num_steps().
  RecordedStep Step(std::size_t i) const;
  /// The laser mount X_RS on R.
  const Pose2& X_RS() const { return X_RS_; }

 private:
  CsvTable scans_;
  CsvTable trajectory_;
  int explored_column_ = -1;
  // The ranges of each scan by its time.
  std::map<double, std::vector<double>> ranges_at_;
  Pose2 X_RS_;
};

}  // namespace mjslam::rundir
