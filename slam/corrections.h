#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/rng.h"
#include "slam/slam_params.h"
#include "slam/slam_state.h"

namespace mjslam::slam {

/// An observation associated with map feature `feature` of a SlamState.
struct MatchedObservation {
  /// Index k of the map feature.
  int feature = -1;
  /// The observation in S: (rho, alpha) canonical for lines, (range, bearing)
  /// for corners.
  Eigen::Vector2d z = Eigen::Vector2d::Zero();
  /// Its covariance R (2x2 SPD).
  Eigen::Matrix2d R = Eigen::Matrix2d::Identity();
  /// d z / d (laser range bias), in z's form (LineObservation's or
  /// CornerObservation's range_bias_gradient); used with self-calibration.
  Eigen::Vector2d range_bias_gradient = Eigen::Vector2d::Zero();
};

/// The paper's selection criterion for one candidate, sum(eig(B_i)) with
/// B_i = I_5 - [K_v; K_z] [H_v H_z], in closed form: since K_vz H_vz =
/// P_b H^T S^-1 H, three eigenvalues of B_i are 1 and the other two are those
/// of S^-1 R, so sum eig(B_i) = 5 - trace(K_vz H_vz) = 3 + trace(S^-1 R),
/// in (3, 5]. S = H P H^T + R and R are 2x2 SPD. Smaller is more informative.
double SelectionCriterion(const Eigen::Matrix2d& S, const Eigen::Matrix2d& R);

/// The 5x5 block B = I_5 - K_b H_b of the paper's Eq. (15) written out, with
/// P_b the pose + feature block of P, H_b = [H_v H_z] (2x5), R (2x2 SPD) and
/// K_b = P_b H_b^T (H_b P_b H_b^T + R)^-1. For tests and documentation; the
/// filter uses SelectionCriterion.
Eigen::Matrix<double, 5, 5> SelectionBlock(const Eigen::Matrix<double, 5, 5>& P_b,
                                           const Eigen::Matrix<double, 2, 5>& H_b,
                                           const Eigen::Matrix2d& R);

/// SelectionCriterion for candidate `observation` with the current P and
/// mean of `state`. O(1).
double SelectionCriterion(const SlamState& state, const MatchedObservation& observation);

/// det of the pose covariance P_pp after correcting `state` with
/// `observation`: det(P_pp - C S^-1 C^T), C = P_(pose,b) H_b^T the pose rows
/// of P H^T, S = H P H^T + R. The determinant policy's score; smaller means
/// the correction shrinks the pose's uncertainty volume more. O(1).
double PoseDeterminantAfter(const SlamState& state, const MatchedObservation& observation);

/// Algorithm 1 (classical sequential EKF): corrects `state` with every
/// matched observation, in order, each re-linearised at the current mean.
/// Returns the number of corrections (matched.size()). O(|M| n^2).
int CorrectClassical(SlamState* state, const std::vector<MatchedObservation>& matched);

/// Algorithm 2 (feature updating selection): min(|M|, max_updates) times,
/// chooses one remaining candidate by `policy`, corrects with it and removes
/// it. kCriterion (the paper's): the argmin of the criterion under the
/// current P; kLeastInformative: its argmax; kDeterminant: the argmin of
/// PoseDeterminantAfter under the current P; kFirst: the first remaining
/// (extraction order); kRandom: one drawn uniformly from `rng`. Ties go to
/// the first. Returns the indices into `matched` in the order they were
/// used. O(MAX (|M| + n^2)).
/// Preconditions (checked): max_updates >= 1; `rng` not null for kRandom.
std::vector<int> CorrectSelective(SlamState* state, const std::vector<MatchedObservation>& matched,
                                  int max_updates,
                                  SelectionPolicy policy = SelectionPolicy::kCriterion,
                                  Rng* rng = nullptr);

}  // namespace mjslam::slam
