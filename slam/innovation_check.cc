#include "slam/innovation_check.h"

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
      mean_(TruncatedMean(gate)),
      variance_(TruncatedVariance(gate)),
      z_(NormalQuantile(params.probability)) {
  MJSLAM_CHECK(gate > 0.0);
  params_.ValidateOrThrow();
  result_.mean_nis = std::numeric_limits<double>::quiet_NaN();
}

void InnovationCheck::Add(double t_s, double nis_sum, int count) {
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
  total_sum_ += nis_sum;
  result_.observations += count;
  if (result_.observations > 0) result_.mean_nis = total_sum_ / result_.observations;
}

void InnovationCheck::CloseWindow() {
  const double sum = window_sum_;
  const long count = window_count_;
  const long steps = window_steps_;
  window_sum_ = 0.0;
  window_count_ = 0;
  window_steps_ = 0;
  if (count == 0) return;  // nothing to judge
  ++result_.windows;
  // The observations of one scan share its pose error: the bound counts
  // scans, not observations, as the independent draws (conservative).
  const double bound = mean_ + z_ * std::sqrt(variance_ / static_cast<double>(steps));
  if (sum / static_cast<double>(count) <= bound) {
    streak_ = 0;
    return;
  }
  ++result_.failed_windows;
  if (streak_ == 0) streak_start_s_ = window_start_s_;
  ++streak_;
  if (streak_ > result_.longest_failed_streak) result_.longest_failed_streak = streak_;
  if (streak_ >= params_.sustained_windows && !result_.inconsistent_since_s) {
    result_.inconsistent_since_s = streak_start_s_;
  }
}

}  // namespace mjslam::slam
