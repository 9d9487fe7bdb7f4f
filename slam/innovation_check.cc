#include "slam/innovation_check.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/check.h"

namespace mjslam::slam {
namespace {

// The standard normal quantile of p in (0, 1), by bisection on erfc (to
// 1e-12; only called once per check).
double NormalQuantile(double p) {
  double lo = -40.0;
  double hi = 40.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12; ++i) {
    const double mid = 0.5 * (lo + hi);
    const double cdf = 0.5 * std::erfc(-mid / std::sqrt(2.0));
    (cdf < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

std::vector<ParamProblem> InnovationCheckParams::Validate() const {
  ParamChecker check;
  check.Positive("window_s", window_s);
  check.Require(probability > 0.5 && probability < 1.0, "probability", probability,
                "a value in (0.5, 1)");
  check.Require(sustained_windows >= 1, "sustained_windows", sustained_windows, "a value >= 1");
  check.Require(near_miss_max_nis >= 0.0 && std::isfinite(near_miss_max_nis), "near_miss_max_nis",
                near_miss_max_nis, "a finite value >= 0 (0: off)");
  check.Require(copies_per_scan >= 0, "copies_per_scan", copies_per_scan,
                "a value >= 0 (0: off)");
  return check.problems();
}

double InnovationCheck::TruncatedMean(double gate) {
  // E[X | X < g] for X exponential with mean 2.
  const double tail = std::exp(-0.5 * gate);
  return 2.0 - gate * tail / (1.0 - tail);
}

double InnovationCheck::TruncatedVariance(double gate) {
  // E[X^2 | X < g] = (8 - e^(-g/2) (g^2 + 4 g + 8)) / (1 - e^(-g/2)).
  const double tail = std::exp(-0.5 * gate);
  const double second = (8.0 - tail * (gate * gate + 4.0 * gate + 8.0)) / (1.0 - tail);
  const double mean = TruncatedMean(gate);
  return second - mean * mean;
}

InnovationCheck::InnovationCheck(const InnovationCheckParams& params, double gate)
    : params_(params),
      gate_(gate),
      mean_(TruncatedMean(gate)),
      variance_(TruncatedVariance(gate)),
      z_(NormalQuantile(params.probability)),
      miss_probability_(std::exp(-0.5 * gate)) {
  MJSLAM_CHECK(gate > 0.0);
  params_.ValidateOrThrow();
  result_.mean_nis = std::numeric_limits<double>::quiet_NaN();
  result_.near_miss_fraction = std::numeric_limits<double>::quiet_NaN();
}

int InnovationCheck::NearMisses(const std::vector<double>& nearest_nis) const {
  int misses = 0;
  for (const double nis : nearest_nis) {
    misses += nis >= gate_ && nis < params_.near_miss_max_nis ? 1 : 0;
  }
  return misses;
}

int InnovationCheck::Copies(const Association& association,
                            const std::vector<double>& nearest_nis) const {
  MJSLAM_CHECK(association.outcome.size() == nearest_nis.size());
  int copies = 0;
  for (std::size_t o = 0; o < nearest_nis.size(); ++o) {
    copies += association.outcome[o] == AssociationOutcome::kNew &&
                      nearest_nis[o] < params_.near_miss_max_nis
                  ? 1
                  : 0;
  }
  return copies;
}

void InnovationCheck::Add(double t_s, double nis_sum, int count, int num_observed,
                          int num_near_misses, int num_copies) {
  if (!window_open_) {
    window_open_ = true;
    window_start_s_ = t_s;
  } else if (t_s >= window_start_s_ + params_.window_s) {
    CloseWindow();
    window_start_s_ = t_s;
  }
  window_sum_ += nis_sum;
  window_count_ += count;
  if (count > 0) ++window_steps_;
  window_observed_ += num_observed;
  window_near_misses_ += num_near_misses;
  if (num_observed > 0) ++window_scans_;
  result_.copies += num_copies;
  if (params_.near_miss_max_nis > 0.0 && params_.copies_per_scan > 0 &&
      num_copies >= params_.copies_per_scan) {
    ++result_.copied_scans;
    if (!result_.map_copied_at_s) result_.map_copied_at_s = t_s;
    ReportInconsistent(t_s);
  }
  total_sum_ += nis_sum;
  result_.observations += count;
  if (result_.observations > 0) result_.mean_nis = total_sum_ / result_.observations;
  total_observed_ += num_observed;
  total_near_misses_ += num_near_misses;
  if (total_observed_ > 0) {
    result_.near_miss_fraction =
        static_cast<double>(total_near_misses_) / static_cast<double>(total_observed_);
  }
}

void InnovationCheck::CloseWindow() {
  JudgeNis();
  if (params_.near_miss_max_nis > 0.0) JudgeNearMisses();
  window_sum_ = 0.0;
  window_count_ = 0;
  window_steps_ = 0;
  window_observed_ = 0;
  window_near_misses_ = 0;
  window_scans_ = 0;
}

void InnovationCheck::JudgeNis() {
  if (window_count_ == 0) return;  // nothing to judge
  ++result_.windows;
  // The observations of one scan share its pose error: the bound counts
  // scans, not observations, as the independent draws (conservative).
  const double bound = mean_ + z_ * std::sqrt(variance_ / static_cast<double>(window_steps_));
  const bool failed = window_sum_ / static_cast<double>(window_count_) > bound;
  if (failed) ++result_.failed_windows;
  Streak(failed, &streak_, &streak_start_s_);
  result_.longest_failed_streak = std::max(result_.longest_failed_streak, streak_);
}

void InnovationCheck::JudgeNearMisses() {
  if (window_observed_ == 0) return;
  ++result_.near_miss_windows;
  const double p0 = miss_probability_;
  const double bound =
      p0 + z_ * std::sqrt(p0 * (1.0 - p0) / static_cast<double>(window_scans_));
  const bool failed = static_cast<double>(window_near_misses_) /
                          static_cast<double>(window_observed_) > bound;
  if (failed) ++result_.near_miss_failed_windows;
  if (Streak(failed, &miss_streak_, &miss_streak_start_s_) && !result_.near_miss_since_s) {
    result_.near_miss_since_s = miss_streak_start_s_;
  }
}

void InnovationCheck::ReportInconsistent(double since_s) {
  if (!result_.inconsistent_since_s || since_s < *result_.inconsistent_since_s) {
    result_.inconsistent_since_s = since_s;
  }
}

bool InnovationCheck::Streak(bool failed, int* streak, double* streak_start_s) {
  if (!failed) {
    *streak = 0;
    return false;
  }
  if (*streak == 0) *streak_start_s = window_start_s_;
  ++*streak;
  if (*streak < params_.sustained_windows) return false;
  ReportInconsistent(*streak_start_s);
  return true;
}

}  // namespace mjslam::slam
