#include "slam/corrections.h"

#include <algorithm>
#include <limits>

#include <Eigen/LU>

#include "common/check.h"

namespace mjslam::slam {

double SelectionCriterion(const Eigen::Matrix2d& S, const Eigen::Matrix2d& R) {
  // trace(S^-1 R) with the 2x2 inverse written out: S^-1 = adj(S) / det(S).
  const double det = S(0, 0) * S(1, 1) - S(0, 1) * S(1, 0);
  MJSLAM_CHECK(det > 0.0);
  const double trace_adj_R = S(1, 1) * R(0, 0) - S(0, 1) * R(1, 0) - S(1, 0) * R(0, 1) +
                             S(0, 0) * R(1, 1);
  return 3.0 + trace_adj_R / det;
}

Eigen::Matrix<double, 5, 5> SelectionBlock(const Eigen::Matrix<double, 5, 5>& P_b,
                                           const Eigen::Matrix<double, 2, 5>& H_b,
                                           const Eigen::Matrix2d& R) {
  Eigen::Matrix2d S;
  S.noalias() = H_b * P_b * H_b.transpose();
  S += R;
  Eigen::Matrix<double, 5, 2> K;
  K.noalias() = P_b * H_b.transpose() * S.inverse();
  Eigen::Matrix<double, 5, 5> B = Eigen::Matrix<double, 5, 5>::Identity();
  B.noalias() -= K * H_b;
  return B;
}

double SelectionCriterion(const SlamState& state, const MatchedObservation& observation) {
  return SelectionCriterion(
      state.InnovationCovariance(observation.feature, observation.z, observation.R),
      observation.R);
}

int CorrectClassical(SlamState* state, const std::vector<MatchedObservation>& matched) {
  for (const MatchedObservation& observation : matched) {
    state->Update(observation.feature, observation.z, observation.R);
  }
  return static_cast<int>(matched.size());
}

std::vector<int> CorrectSelective(SlamState* state, const std::vector<MatchedObservation>& matched,
                                  int max_updates) {
  MJSLAM_CHECK(max_updates >= 1);
  std::vector<int> remaining(matched.size());
  for (std::size_t i = 0; i < matched.size(); ++i) remaining[i] = static_cast<int>(i);
  std::vector<int> used;
  const int rounds = std::min(static_cast<int>(matched.size()), max_updates);
  for (int round = 0; round < rounds; ++round) {
    // The candidate with the smallest eigenvalue sum under the current P.
    int best = -1;
    double best_criterion = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < remaining.size(); ++i) {
      const double criterion = SelectionCriterion(*state, matched[remaining[i]]);
      if (criterion < best_criterion) {
        best_criterion = criterion;
        best = static_cast<int>(i);
      }
    }
    MJSLAM_CHECK(best >= 0);

    // Correct with it (as in Algorithm 1) and drop it from the candidates.
    const MatchedObservation& chosen = matched[remaining[best]];
    state->Update(chosen.feature, chosen.z, chosen.R);
    used.push_back(remaining[best]);
    remaining.erase(remaining.begin() + best);
  }
  return used;
}

}  // namespace mjslam::slam
