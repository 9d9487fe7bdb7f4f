#include "eval/map_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>

#include "common/angles.h"
#include "common/chi_square.h"

namespace mjslam::eval {

std::vector<ParamProblem> MatchParams::Validate() const {
  ParamChecker check;
  check.Positive("line_rho_gate_m", line_rho_gate_m);
  check.Positive("line_alpha_gate_rad", line_alpha_gate_rad);
  check.Positive("line_segment_gap_gate_m", line_segment_gap_gate_m);
  check.Positive("corner_gate_m", corner_gate_m);
  check.Require(inconsistent_probability > 0.0 && inconsistent_probability < 1.0,
                "inconsistent_probability", inconsistent_probability, "a value in (0, 1)");
  return check.problems();
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The parameter error of a line estimate against a true line, in the true
// line's polar form nearest to the estimate.
Eigen::Vector2d LineError(const MapFeature& estimate, const MapFeature& truth) {
  const Eigen::Vector2d direct(estimate.params.x() - truth.params.x(),
                               WrapAngle(estimate.params.y() - truth.params.y()));
  const Eigen::Vector2d flipped(estimate.params.x() + truth.params.x(),
                                WrapAngle(estimate.params.y() - truth.params.y() - kPi));
  return std::abs(direct.y()) <= std::abs(flipped.y()) ? direct : flipped;
}

// Gap between the estimate's segment and the true segment along the true line.
double SegmentGap(const MapFeature& estimate, const MapFeature& truth) {
  if (!estimate.has_segment || !truth.has_segment) return 0.0;
  const Eigen::Vector2d d = truth.p_WB - truth.p_WA;
  const double length = d.norm();
  if (length <= 0.0) return 0.0;
  const Eigen::Vector2d t = d / length;
  const double e0 = t.dot(estimate.p_WA - truth.p_WA);
  const double e1 = t.dot(estimate.p_WB - truth.p_WA);
  const double lo = std::min(e0, e1);
  const double hi = std::max(e0, e1);
  if (hi < 0.0) return -hi;
  if (lo > length) return lo - length;
  return 0.0;
}

double Nees(const Eigen::Vector2d& error, const Eigen::Matrix2d& covariance) {
  const Eigen::LLT<Eigen::Matrix2d> llt(covariance);
  if (llt.info() != Eigen::Success || covariance.diagonal().minCoeff() <= 0.0) return kNaN;
  return llt.matrixL().solve(error).squaredNorm();
}

}  // namespace

MapMatchReport MatchMaps(const Map& estimate, const Map& truth, const MatchParams& params) {
  params.ValidateOrThrow();
  MapMatchReport report;
  report.num_estimates = static_cast<int>(estimate.size());
  report.num_truth = static_cast<int>(truth.size());
  report.truth_index.assign(estimate.size(), -1);
  report.nees.assign(estimate.size(), kNaN);
  const double inconsistent_above = ChiSquareQuantile(params.inconsistent_probability, 2.0);

  std::vector<int> matches_of_truth(truth.size(), 0);
  double nees_sum = 0.0;
  int nees_count = 0;
  double rho_sq = 0.0;
  double alpha_sq = 0.0;
  double corner_sq = 0.0;
  int num_lines = 0;
  int num_corners = 0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const MapFeature& e = estimate[i];
    int best = -1;
    double best_distance = 1.0;
    Eigen::Vector2d best_error = Eigen::Vector2d::Zero();
    for (std::size_t j = 0; j < truth.size(); ++j) {
      const MapFeature& t = truth[j];
      if (t.type != e.type) continue;
      Eigen::Vector2d error;
      double distance = 0.0;
      if (e.type == MapFeature::Type::kLine) {
        error = LineError(e, t);
        const double gap = SegmentGap(e, t);
        distance = std::pow(error.x() / params.line_rho_gate_m, 2) +
                   std::pow(error.y() / params.line_alpha_gate_rad, 2) +
                   std::pow(gap / params.line_segment_gap_gate_m, 2);
      } else {
        error = e.params - t.params;
        distance = error.squaredNorm() / (params.corner_gate_m * params.corner_gate_m);
      }
      if (distance <= best_distance) {
        best = static_cast<int>(j);
        best_distance = distance;
        best_error = error;
      }
    }
    if (best < 0) {
      ++report.num_unmatched_estimates;
      continue;
    }
    report.truth_index[i] = best;
    ++report.num_matched_estimates;
    if (++matches_of_truth[best] > 1) ++report.num_duplicates;
    const double nees = Nees(best_error, e.covariance);
    report.nees[i] = nees;
    if (std::isfinite(nees)) {
      nees_sum += nees;
      ++nees_count;
      if (nees > inconsistent_above) ++report.num_inconsistent;
    }
    if (e.type == MapFeature::Type::kLine) {
      rho_sq += best_error.x() * best_error.x();
      alpha_sq += best_error.y() * best_error.y();
      ++num_lines;
    } else {
      corner_sq += best_error.squaredNorm();
      ++num_corners;
    }
  }
  for (const int count : matches_of_truth) {
    if (count > 0) ++report.num_matched_truth;
  }
  report.matched_fraction =
      truth.empty() ? 0.0 : static_cast<double>(report.num_matched_truth) / truth.size();
  report.mean_nees = nees_count > 0 ? nees_sum / nees_count : kNaN;
  report.line_rho_rmse_m = num_lines > 0 ? std::sqrt(rho_sq / num_lines) : kNaN;
  report.line_alpha_rmse_rad = num_lines > 0 ? std::sqrt(alpha_sq / num_lines) : kNaN;
  report.corner_rmse_m = num_corners > 0 ? std::sqrt(corner_sq / num_corners) : kNaN;
  return report;
}

SeenMatch MatchedSeen(const MapMatchReport& report, const std::vector<char>& seen) {
  if (static_cast<int>(seen.size()) != report.num_truth) {
    throw std::invalid_argument("MatchedSeen: " + std::to_string(seen.size()) +
                                " seen flags for " + std::to_string(report.num_truth) +
                                " true features");
  }
  std::vector<char> matched(seen.size(), 0);
  for (const int t : report.truth_index) {
    if (t >= 0) matched[t] = 1;
  }
  SeenMatch result;
  int both = 0;
  for (std::size_t t = 0; t < seen.size(); ++t) {
    if (seen[t] == 0) continue;
    ++result.seen;
    if (matched[t] != 0) ++both;
  }
  if (result.seen > 0) result.matched_fraction = static_cast<double>(both) / result.seen;
  return result;
}

}  // namespace mjslam::eval
