#pragma once

#include <optional>
#include <vector>

#include "common/params.h"
#include "slam/data_association.h"

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
  /// Near misses: an observation that matched nothing but lies within this
  /// NIS of a map feature of its kind (at or above the gate) is counted as
  /// one (>= 0; 0 turns the near-miss test off). A filter whose pose or map is
  /// a few sigma off sees the walls it mapped just outside the gate.
  double near_miss_max_nis = 100.0;
  /// Copies: an observation that became a new feature although a map
  /// feature of its kind lies within NIS `near_miss_max_nis` is a copy of
  /// mapped structure. A scan with at least this many copies reports the
  /// map copied (>= 0; 0 turns the copy test off).
  int copies_per_scan = 3;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(window_s));
    a->Visit(MJSLAM_NVP(probability));
    a->Visit(MJSLAM_NVP(sustained_windows));
    a->Visit(MJSLAM_NVP(near_miss_max_nis));
    a->Visit(MJSLAM_NVP(copies_per_scan));
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
  /// Windows with observations judged by the near-miss test, those that
  /// failed, and the fraction of all observations of the run that were near
  /// misses (NaN: none observed).
  int near_miss_windows = 0;
  int near_miss_failed_windows = 0;
  double near_miss_fraction = 0.0;
  /// Start time of the first streak of `sustained_windows` windows failing
  /// the near-miss test (none: never).
  std::optional<double> near_miss_since_s;
  /// Copies over the run (new features within NIS `near_miss_max_nis` of a
  /// mapped feature of their kind), and the scans with at least
  /// `copies_per_scan` of them.
  long copies = 0;
  int copied_scans = 0;
  /// Time of the first scan with at least `copies_per_scan` copies (none:
  /// never): the filter added a copy of what it had mapped, the signature
  /// of a lost pose.
  std::optional<double> map_copied_at_s;
  /// The earliest of: the start of the first streak of `sustained_windows`
  /// failing windows of the NIS or near-miss test, and map_copied_at_s, the earlier (none: the filter stayed consistent with
  /// its innovations).
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
///
/// The matched NIS alone cannot see a filter that lost its map: a wrong pose
/// moves the observations of mapped walls out of the gate, and what still
/// matches has a small NIS. The second, near-miss test counts those: an
/// observation that matched nothing although a feature of its kind lies
/// within `near_miss_max_nis` (NIS at or above the gate g). Observed from
/// a consistent filter, a mapped feature's NIS exceeds g with probability
/// p0 = e^(-g/2) (0.01 at the 0.99 gate); new structure lies far from every
/// feature. A window fails when its fraction of near misses among its
/// observations exceeds p0 + z_p sqrt(p0 (1 - p0) / K), with K its scans
/// with observations (the observations of a scan share its pose error).
///
/// Neither test sees the loss when every observation of a scan misses the
/// gate at once and becomes a new feature (the paper's rule of new
/// features; EkfParams::new_features_need_match false): that scan's
/// observations are not near misses, and the next scans match the copies it
/// made. The third, copy test counts the new features that lie within
/// `near_miss_max_nis` of a mapped feature of their kind (at or above the
/// new-feature threshold): a scan with `copies_per_scan` of them reports the
/// map copied at once. Its threshold is set from measured runs, not from a
/// law: healthy runs add at most one copy per scan (docs/results.md, "The
/// maze map loss").
class InnovationCheck {
 public:
  /// `gate`: the association gate on NIS (> 0), e.g. ChiSquare2Quantile(0.99).
  InnovationCheck(const InnovationCheckParams& params, double gate);

  /// Adds one step at time `t_s` (non-decreasing): the sum of the NIS of its
  /// `count` matched observations (no near-miss data: each observation
  /// counts as matched).
  void Add(double t_s, double nis_sum, int count) { Add(t_s, nis_sum, count, count, 0); }
  /// Adds one step with its `num_observed` observations, of which
  /// `num_near_misses` were near misses (NearMisses).
  void Add(double t_s, double nis_sum, int count, int num_observed, int num_near_misses) {
    Add(t_s, nis_sum, count, num_observed, num_near_misses, 0);
  }
  /// Adds one step with its near misses and its `num_copies` copies (Copies).
  void Add(double t_s, double nis_sum, int count, int num_observed, int num_near_misses,
           int num_copies);

  /// The near misses among a scan's observations given each one's nearest
  /// NIS to a map feature of its kind (slam::StepReport::nearest_nis):
  /// those in [gate, near_miss_max_nis).
  int NearMisses(const std::vector<double>& nearest_nis) const;
  /// The copies among a scan's observations: those that became new features
  /// (AssociationOutcome::kNew) with `nearest_nis` below near_miss_max_nis.
  int Copies(const Association& association, const std::vector<double>& nearest_nis) const;

  /// The result so far (the open window left out).
  InnovationCheckResult result() const { return result_; }

  /// Mean and variance of the 2-dof chi-square truncated at `gate`.
  static double TruncatedMean(double gate);
  static double TruncatedVariance(double gate);

 private:
  void CloseWindow();
  // The two tests of a closed window.
  void JudgeNis();
  void JudgeNearMisses();
  // Sets inconsistent_since_s to `since_s` unless it is set earlier.
  void ReportInconsistent(double since_s);
  // Updates a streak of failing windows with this window's verdict; when the
  // streak is sustained, sets inconsistent_since_s (the earliest) and
  // returns true.
  bool Streak(bool failed, int* streak, double* streak_start_s);

  InnovationCheckParams params_;
  double gate_;
  double mean_;
  double variance_;
  double z_;
  double miss_probability_;
  double window_start_s_ = 0.0;
  bool window_open_ = false;
  double window_sum_ = 0.0;
  long window_count_ = 0;
  long window_steps_ = 0;
  long window_observed_ = 0;
  long window_near_misses_ = 0;
  long window_scans_ = 0;
  int streak_ = 0;
  double streak_start_s_ = 0.0;
  int miss_streak_ = 0;
  double miss_streak_start_s_ = 0.0;
  double total_sum_ = 0.0;
  long total_observed_ = 0;
  long total_near_misses_ = 0;
  InnovationCheckResult result_;
};

}  // namespace mjslam::slam
