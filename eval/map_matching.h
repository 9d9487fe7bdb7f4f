#pragma once

#include <limits>
#include <vector>

#include "common/params.h"
#include "eval/map_types.h"

namespace mjslam::eval {

/// Gates of MatchMaps. An estimate matches a true feature of its type when its
/// normalised distance sum_k (delta_k / gate_k)^2 is at most 1.
struct MatchParams {
  /// Lines: difference of r, metres, and of al, radians.
  double line_rho_gate_m = 0.15;
  double line_alpha_gate_rad = 0.1;
  /// Lines: the gap between the estimate's seen segment and the true
  /// segment, measured along the true line (0 when they overlap), metres.
  double line_segment_gap_gate_m = 0.3;
  /// Corners: distance between the points, metres.
  double corner_gate_m = 0.15;
  /// A matched estimate whose feature NEES (2 dof) exceeds the chi-square
  /// quantile of this probability is counted inconsistent.
  double inconsistent_probability = 0.999;

  std::vector<ParamProblem> Validate() const;
  void ValidateOrThrow() const { ThrowIfProblems(Validate(), "map matching"); }
};

/// How an estimated map compares with the true one.
struct MapMatchReport {
  /// For each estimated feature, the index in the true map of its match, or
  /// -1 (no true feature of its type within the gate).
  std::vector<int> truth_index;
  /// For each estimated feature, its NEES against the match (2 dof: the
  /// parameter error through the estimate's covariance, the line angle
  /// wrapped); NaN when unmatched or the covariance is not positive definite.
  std::vector<double> nees;

  int num_estimates = 0;
  int num_truth = 0;
  /// Estimates with a match; true features with at least one.
  int num_matched_estimates = 0;
  int num_matched_truth = 0;
  /// num_matched_truth / num_truth (0 for an empty truth).
  double matched_fraction = 0.0;
  /// Estimates beyond the first matched to one true feature: two estimates
  /// of one wall or corner (a missed association).
  int num_duplicates = 0;
  /// Estimates within no gate: features that lie on no true wall or corner
  /// (made of wrong associations, or spurious).
  int num_unmatched_estimates = 0;
  /// Matched estimates whose NEES exceeds the inconsistent_probability
  /// quantile: pulled off their true feature (typically by wrong
  /// associations) or overconfident.
  int num_inconsistent = 0;
  /// Mean of the defined NEES values (NaN if none).
  double mean_nees = 0.0;
  /// RMS of the matched errors: lines' r (m) and al (rad), corners' position
  /// (m); NaN when there are none of that type.
  double line_rho_rmse_m = 0.0;
  double line_alpha_rmse_rad = 0.0;
  double corner_rmse_m = 0.0;
};

/// Matches every estimated feature to the nearest true feature of the same
/// type by geometry (MatchParams), independently (many estimates may match one
/// true feature: duplicates). A line is compared with both polar forms of the
/// true line ((r, al) and (-r, al + pi)), so lines through W's origin match.
/// Throws ParamError for invalid params.
MapMatchReport MatchMaps(const Map& estimate, const Map& truth, const MatchParams& params = {});

/// The true features a run saw and how many of them a map matched.
struct SeenMatch {
  int seen = 0;
  /// Seen true features with a matched estimate / seen (NaN when none is).
  double matched_fraction = std::numeric_limits<double>::quiet_NaN();
};

/// SeenMatch of `report` (MatchMaps against the truth) given `seen`, one
/// entry per true feature, nonzero where the run saw it. Throws
/// std::invalid_argument when the sizes differ.
SeenMatch MatchedSeen(const MapMatchReport& report, const std::vector<char>& seen);

}  // namespace mjslam::eval
