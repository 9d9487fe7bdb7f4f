#pragma once

#include <optional>
#include <vector>

#include "common/params.h"

namespace mjslam::slam {

/// Settings of the innovation consistency check (`slam.innovation_check.*`;
/// docs/method.md, "Innovation consistency check").
struct InnovationCheckParams {
  /// Length of one window of simulated time, seconds (> 0).
  double window_s = 5.0;
  /// A window fails when the mean NIS of its matched observations is above
  /// the upper quantile of this probability of its distribution under a
  /// consistent filter, in (0.5, 1).
  double probability = 0.999;
  /// The filter is reported inconsistent after this many failing windows in
  /// a row (>= 1).
  int sustained_windows = 3;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(window_s));
    a->Visit(MJSLAM_NVP(probability));
    a->Visit(MJSLAM_NVP(sustained_windows));
  }
  /// Every out-of-range field, keys relative to this struct.
  std::vector<ParamProblem> Validate() const;
  /// Throws ParamError listing every problem of Validate().
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }
};

/// What InnovationCheck found over a run.
struct InnovationCheckResult {
  /// Windows closed, and those that failed.
  int windows = 0;
  int failed_windows = 0;
  /// The longest run of consecutive failing windows.
  int longest_failed_streak = 0;
  /// Mean NIS of all matched observations of the run (NaN: none), and how
  /// many there were.
  double mean_nis = 0.0;
  long observations = 0;
  /// Start time of the first streak of `sustained_windows` failing windows
  /// (none: the filter stayed consistent with its innovations).
  std::optional<double> inconsistent_since_s;
  /// Whether such a streak happened.
  bool inconsistent() const { return inconsistent_since_s.has_value(); }
};

/// A windowed test of a filter's innovations against its own covariance.
/// For a consistent filter, the normalised innovation squared NIS = nu^T
/// S^-1 nu of an observation matched to its true feature is chi-square with
/// 2 dof, truncated at the association gate g: mean m = 2 - g e^(-g/2) /
/// (1 - e^(-g/2)), variance v from the same law. The mean NIS of the matched
/// observations of a window has mean m; the observations of one scan share
/// its pose error, so the window's K steps with matches, not its
/// observations, are taken as the independent draws: the window fails when
/// its mean NIS exceeds m + z_p sqrt(v / K) (z_p the normal quantile of
/// `probability`). A filter that lost its map or is
/// overconfident shifts its matched NIS toward the gate, and fails windows
/// in a row. Windows with no matched observation neither pass nor fail.
class InnovationCheck {
 public:
  /// `gate`: the association gate on NIS (> 0), e.g. ChiSquare2Quantile(0.99).
  InnovationCheck(const InnovationCheckParams& params, double gate);

  /// Adds one step at time `t_s` (non-decreasing): the sum of the NIS of its
  /// `count` matched observations.
  void Add(double t_s, double nis_sum, int count);

  /// The result so far (the open window left out).
  InnovationCheckResult result() const { return result_; }

  /// Mean and variance of the 2-dof chi-square truncated at `gate`.
  static double TruncatedMean(double gate);
  static double TruncatedVariance(double gate);

 private:
  void CloseWindow();

  InnovationCheckParams params_;
  double mean_;
  double variance_;
  double z_;
  double window_start_s_ = 0.0;
  bool window_open_ = false;
  double window_sum_ = 0.0;
  long window_count_ = 0;
  long window_steps_ = 0;
  int streak_ = 0;
  double streak_start_s_ = 0.0;
  double total_sum_ = 0.0;
  InnovationCheckResult result_;
};

}  // namespace mjslam::slam
