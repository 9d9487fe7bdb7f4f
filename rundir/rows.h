#pragma once

// The rows of a run directory's CSV files as plain data, and their writers
// and readers (columns: rundir/layout.h).
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/pose2.h"
#include "common/records.h"
#include "rundir/csv_reader.h"
#include "rundir/csv_writer.h"

namespace mjslam::rundir {

/// One filter's columns of a trajectory.csv row (FilterColumnSuffixes()).
struct FilterRow {
  /// The filter's name, the prefix of its columns (set by the reader; the
  /// writer takes the names from the header it was given).
  std::string name;
  /// The estimate of R in W after the step, and its 3x3 pose covariance
  /// (x, y, th; metres, radians).
  Pose2 X_WR;
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
  /// Map size, observations matched, observations used in the correction.
  int num_features = 0;
  int num_matched = 0;
  int num_updated = 0;
  /// Measured processing time of the step, microseconds.
  double processing_us = 0.0;
  /// The command period the step's processing imposes, and the open-loop
  /// time so far on the filter's own command timeline, seconds.
  double period_s = 0.0;
  double open_loop_s = 0.0;
  /// Pose NEES of the step (3 dof); not finite: written as an empty field.
  double nees = 0.0;
  /// Whether the filter processed the step's record (written 1 or 0): false
  /// when, in realtime timing, it was still busy with an earlier one and
  /// the fields above hold its last processed estimate.
  bool processed = true;
};

/// One row of trajectory.csv (TrajectoryColumns()).
struct TrajectoryRow {
  /// Time of the step, seconds.
  double t_s = 0.0;
  /// True pose and wheel-odometry pose of R in W.
  Pose2 X_WR_true;
  Pose2 X_WR_odometry;
  /// The command applied from t_s to the next step.
  Twist2 command;
  /// Explored fraction in [0, 1]; not finite: written as an empty field
  /// (a replay of a recording that has none).
  double explored = 0.0;
  /// One per filter, in the order of the file's columns.
  std::vector<FilterRow> filters;
};

/// Appends `row` to a trajectory.csv writer (numbers shortest round-trip).
void AddTrajectoryRow(const TrajectoryRow& row, CsvWriter* trajectory);

/// Appends a row of scans.csv: time, the true laser pose X_WS and the
/// ranges, metres.
void AddScanRow(double t_s, const Pose2& X_WS, const std::vector<double>& ranges_m,
                CsvWriter* scans);

/// The explorer's sets at one time, as explorer.csv stores them (points in W,
/// metres): candidate frontier points, the goal, the planned path in order.
struct ExplorerSnapshot {
  double t_s = 0.0;
  std::vector<Eigen::Vector2d> frontier;
  std::optional<Eigen::Vector2d> goal;
  std::vector<Eigen::Vector2d> path;
};

/// Appends the rows of `snapshot` to an explorer.csv writer: kind
/// "frontier", "goal" and "path", each with its index.
void AddExplorerRows(const ExplorerSnapshot& snapshot, CsvWriter* explorer);

/// Coordinates and ranges beyond this are no building's (metres): a damaged
/// file, not a run.
inline constexpr double kMaxRecordedCoordinateM = 1e6;

/// Reads a trajectory.csv: at least one row; the recorded columns
/// (RecordedTrajectoryColumns()) first, in order; times finite and
/// increasing; odometry poses and commands finite, within
/// kMaxRecordedCoordinateM; true poses the same, or NaN in every row (a
/// recording without truth, as mjslam import writes). Throws std::runtime_error naming the file, line,
/// column and value of the first problem.
CsvTable ReadTrajectoryCsv(const std::string& path);

/// Reads a scans.csv: columns t, x, y, th, then ranges; times finite and
/// increasing; true laser poses finite (or NaN in every row: a recording
/// without truth), ranges in [0, kMaxRecordedCoordinateM] metres. No rows is allowed (a run too short to scan). Throws
/// std::runtime_error naming the file, line, column and value of the first
/// problem.
CsvTable ReadScansCsv(const std::string& path);

/// Reads a trajectory.csv into its rows, the inverse of AddTrajectoryRow:
/// the checks of ReadTrajectoryCsv (the recorded columns first, in order),
/// then the other columns of TrajectoryColumns(names) by name, in any order,
/// none twice and no other, the filters' names those of the columns
/// `<name>_x` (TrajectoryFilterNames), each with all its columns (none: a
/// recording, `filters` empty); "explored" and each filter's
/// "_period", "_open_loop", "_nees" and "_processed" may be missing (runs
/// from before them): NaN, and processed true. Poses go through Pose2's
/// constructor (angles wrapped), P is the symmetric matrix of its upper
/// triangle, an empty field is NaN. Throws std::runtime_error naming the
/// file, line, column and value of the first problem (a column unknown,
/// twice or missing, a count that is not a whole number in [0, 1e9], a
/// processed flag not 0 or 1).
std::vector<TrajectoryRow> ReadTrajectoryRows(const std::string& path);

/// One row of scans.csv.
struct ScanRow {
  /// Time of the scan, seconds.
  double t_s = 0.0;
  /// True pose of the laser S in W (NaN in a recording without truth).
  Pose2 X_WS;
  /// The ranges, metres, in the order of the beams.
  std::vector<double> ranges_m;
};

/// Reads a scans.csv into its rows, with the checks of ReadScansCsv (the
/// pose through Pose2's constructor). Throws std::runtime_error naming the
/// file, line, column and value of the first problem.
std::vector<ScanRow> ReadScanRows(const std::string& path);

/// One row of reference.csv: the pose of R that an imported log carries at
/// one of its scans.
struct ReferenceRow {
  /// Time of the scan, seconds.
  double t_s = 0.0;
  Pose2 X_WR;
};

/// Reads a reference.csv (ReferenceColumns(), exactly; times finite and
/// increasing; the pose through Pose2's constructor). Throws
/// std::runtime_error naming the file, line, column and value of the first
/// problem.
std::vector<ReferenceRow> ReadReferenceRows(const std::string& path);

/// Reads explorer.csv into its snapshots, in the order of time (rows of one
/// time form one snapshot; path points sorted by index). A missing file
/// gives none. Throws std::runtime_error naming the file and line of an
/// unknown kind.
std::vector<ExplorerSnapshot> ReadExplorerCsv(const std::string& path);

}  // namespace mjslam::rundir
