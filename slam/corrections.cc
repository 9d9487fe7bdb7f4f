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
      state.InnovationCovariance(observation.feature, observation.z, observation.R,
                                 observation.range_bias_gradient),
      observation.R);
}

double PoseDeterminantAfter(const SlamState& state, const MatchedObservation& observation) {
  const SlamState::Measurement m = state.MeasureFor(observation.feature, observation.z, observation.range_bias_gradient);
  MJSLAM_CHECK(m.valid);
  Eigen::Matrix<double, 2, 5> H_b;
  H_b << m.H_pose, m.H_feature;
  const Eigen::Matrix2d S = m.HPHt + observation.R;
  const Eigen::Matrix<double, 5, 5> P_b = state.JointCovariance(observation.feature);
  const Eigen::Matrix<double, 3, 2> C = P_b.topRows<3>() * H_b.transpose();
  const Eigen::Matrix3d P_pp = P_b.topLeftCorner<3, 3>() - C * S.inverse() * C.transpose();
  return P_pp.determinant();
}

int CorrectClassical(SlamState* state, const std::vector<MatchedObservation>& matched) {
  for (const MatchedObservation& observation : matched) {
    state->Update(observation.feature, observation.z, observation.R,
                  observation.range_bias_gradient);
  }
  return static_cast<int>(matched.size());
}

namespace {

// The position in `remaining` of the candidate `policy` chooses under the
// current state (CorrectSelective documents the policies).
int ChooseCandidate(const SlamState& state, const std::vector<MatchedObservation>& matched,
                    const std::vector<int>& remaining, SelectionPolicy policy, Rng* rng) {
  const int count = static_cast<int>(remaining.size());
  if (policy == SelectionPolicy::kFirst) return 0;
  if (policy == SelectionPolicy::kRandom) {
    MJSLAM_CHECK(rng != nullptr);
    return std::min(count - 1, static_cast<int>(rng->Uniform() * count));
  }
  // The argmin of a score, ties to the first.
  int best = -1;
  double best_score = std::numeric_limits<double>::infinity();
  for (int i = 0; i < count; ++i) {
    const MatchedObservation& candidate = matched[remaining[i]];
    double score;
    if (policy == SelectionPolicy::kDeterminant) {
      score = PoseDeterminantAfter(state, candidate);
    } else if (policy == SelectionPolicy::kLeastInformative) {
      score = -SelectionCriterion(state, candidate);
    } else {
      // The paper's: the smallest eigenvalue sum.
      score = SelectionCriterion(state, candidate);
    }
    if (score < best_score) {
      best_score = score;
      best = i;
    }
  }
  MJSLAM_CHECK(best >= 0);
  return best;
}

}  // namespace

std::vector<int> CorrectSelective(SlamState* state, const std::vector<MatchedObservation>& matched,
                                  int max_updates, SelectionPolicy policy, Rng* rng) {
  MJSLAM_CHECK(max_updates >= 1);
  std::vector<int> remaining(matched.size());
  for (std::size_t i = 0; i < matched.size(); ++i) remaining[i] = static_cast<int>(i);
  std::vector<int> used;
  const int rounds = std::min(static_cast<int>(matched.size()), max_updates);
  for (int round = 0; round < rounds; ++round) {
    const int best = ChooseCandidate(*state, matched, remaining, policy, rng);

    // Correct with it (as in Algorithm 1) and drop it from the candidates.
    const MatchedObservation& chosen = matched[remaining[best]];
    state->Update(chosen.feature, chosen.z, chosen.R, chosen.range_bias_gradient);
    used.push_back(remaining[best]);
    remaining.erase(remaining.begin() + best);
  }
  return used;
}

}  // namespace mjslam::slam
