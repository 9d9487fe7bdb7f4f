#pragma once

#include <string>
#include <vector>

#include "realdata/relations.h"

namespace mjslam::app {

/// Whether `run_dir` was written by `mjslam import` (manifest mode "import"),
/// or is a replay of such a run (its scans_file lies in one). A replay keeps
/// no relations file or reference: evaluating it checks the covariances only.
bool IsImportedRun(const std::string& run_dir);

/// The scans.csv of an imported run: its own, or for a replay of one the
/// manifest's scans_file.
std::string ImportedScansPath(const std::string& run_dir);

/// The relation metric of one trajectory on one set of relations.
struct ScoredTrajectory {
  /// A filter's name (trajectory.csv's), "odometry" or "reference".
  std::string name;
  realdata::RelationErrors errors;
};

/// What EvaluateImportedRun found (docs/real_data.md, "Scoring").
struct RealEvaluation {
  /// The run's filters, from trajectory.csv's header, in its order: the
  /// order of the filters in the sets below (each set: the filters, then
  /// the odometry, then the reference where it is scored) and in the
  /// per-filter lists.
  std::vector<std::string> filter_names;
  /// On the relations file (empty without one), poses at the scans: the
  /// filters, the odometry and the reference (when there is one), each on
  /// the same relations.
  std::vector<ScoredTrajectory> at_scans;
  /// The same, poses at every record (scans and odometry messages): the
  /// filters and the odometry.
  std::vector<ScoredTrajectory> at_records;
  /// On the relations between scans of the reference trajectory
  /// kReferenceLags[i] apart (1: consecutive scans; 10, 100), each scan to
  /// the one that many scans later (empty without a reference): the filters
  /// and the odometry, over short and long stretches.
  static constexpr int kReferenceLags[] = {1, 10, 100};
  std::vector<std::vector<ScoredTrajectory>> vs_reference_lags;
  /// Relation timestamps (distinct) and how many fell on a scan.
  int relation_times = 0;
  int relation_times_at_scans = 0;
  double time_offset_s = 0.0;
  double tolerance_s = 0.0;
  /// Per filter of filter_names: rows whose pose covariance is not
  /// positive semi-definite (an eigenvalue below -1e-9 of the largest), rows
  /// where it is singular (the smallest eigenvalue at most 1e-9 of the
  /// largest: the known start, and the first steps, before a turn makes the
  /// lateral direction uncertain), and the final map size.
  std::vector<int> not_positive_semidefinite;
  std::vector<int> singular;
  std::vector<int> num_features;
};

/// Scores an imported run (relations from the manifest's relations_file,
/// time offset and tolerance; the reference from reference.csv), poses of
/// the robot centre (frame R moved back by slam.ekf.control_point_offset_m
/// of its config.yaml) and merges the result into summary.json under
/// `real`. Throws std::runtime_error naming a missing or bad file.
RealEvaluation EvaluateImportedRun(const std::string& run_dir);

}  // namespace mjslam::app
