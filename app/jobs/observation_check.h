#pragma once

// The line observations of a run against the true walls: whether the
// extractor's covariances hold (docs/method.md, "The line extractor's fit
// test"), independently of any filter.

#include <limits>
#include <string>
#include <vector>

#include "app/engine/run_config.h"
#include "eval/map_types.h"

namespace mjslam::app {

/// What CheckLineObservations measured over a run's scans.
struct ObservationCheck {
  /// Lines extracted, and those lying on a true wall.
  int lines = 0;
  int matched = 0;
  /// The run's laser range bias, estimated from the matched lines' residuals
  /// (weighted least squares along each line's range-bias gradient), metres.
  double range_bias_m = 0.0;
  /// Of the matched lines, bias removed: the mean NIS against the true wall
  /// (2 for a consistent extractor, chi-square with 2 dof), the fraction above
  /// the association gate 9.21 (0.01), and the largest. NaN without matches.
  double mean_nis = std::numeric_limits<double>::quiet_NaN();
  double fraction_above_gate = std::numeric_limits<double>::quiet_NaN();
  double max_nis = std::numeric_limits<double>::quiet_NaN();
  /// For each feature of the truth, whether the laser saw it: a line that an
  /// extracted line lay on, a corner within `max_corner_distance_m` of an
  /// extracted corner (1), or not (0).
  std::vector<char> seen;
};

/// Re-extracts every scan of `scans_path` (scans.csv of a simulated run) with
/// `config.slam.features` and the laser geometry of `config.laser`, places
/// each line with the scan's true laser pose, and matches it to the true line
/// of `truth` that both ends of its seen segment lie within
/// `max_distance_m` of (the nearest, its seen segment overlapping the true
/// segment); then compares each matched observation z, covariance R, with
/// the true line seen from the true pose: NIS = nu^T R^-1 nu, nu = z - h_true
/// - g b, g the observation's range-bias gradient and b the run's estimated
/// range bias. Every extracted corner placed the same way marks the nearest
/// true corner within `max_corner_distance_m` seen. Throws
/// std::runtime_error naming the file on bad input.
ObservationCheck CheckLineObservations(const std::string& scans_path, const RunConfig& config,
                                       const eval::Map& truth, double max_distance_m = 0.05,
                                       double max_corner_distance_m = 0.15);

}  // namespace mjslam::app
