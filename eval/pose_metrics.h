#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "common/pose2.h"

namespace mjslam::eval {

/// The error of one pose estimate against the truth.
struct PoseStepMetrics {
  /// estimate - truth: x, y (metres) and heading (radians, wrapped to
  /// (-pi, pi]).
  Eigen::Vector3d error = Eigen::Vector3d::Zero();
  /// Pose NEES error^T P^-1 error (3 dof); NaN when P is not positive
  /// definite or nearly singular (smallest eigenvalue <= 1e-12 times the
  /// largest): the known start pose (P = 0) and the first steps after it,
  /// where P has the rank of the input noise.
  double nees = 0.0;
  /// |error_k| <= 2 sqrt(P_kk) per component (a zero error with zero
  /// variance counts as inside).
  std::array<bool, 3> inside_2sigma = {false, false, false};
};

/// Metrics of one step. `P_pose` is the 3x3 covariance of (x, y, th) of the
/// estimate (symmetric; not checked).
PoseStepMetrics EvaluatePoseStep(const Pose2& X_W_true, const Pose2& X_W_estimate,
                                 const Eigen::Matrix3d& P_pose);

/// The summary of a run's steps.
struct PoseSummary {
  int num_steps = 0;
  /// Steps with a defined NEES (P positive definite).
  int num_nees_steps = 0;
  /// Fraction of the steps inside 2 sigma, per component x, y, th.
  Eigen::Vector3d inside_2sigma = Eigen::Vector3d::Zero();
  /// Root mean square error per component (metres, metres, radians).
  Eigen::Vector3d rmse = Eigen::Vector3d::Zero();
  /// Mean pose NEES over the steps where it is defined (NaN if none).
  double mean_nees = 0.0;
  /// The error of the last step.
  Eigen::Vector3d final_error = Eigen::Vector3d::Zero();
};

/// Summarises a run's steps, in time order. An empty run gives zeros and NaN
/// mean_nees.
PoseSummary SummarisePoseSteps(const std::vector<PoseStepMetrics>& steps);

}  // namespace mjslam::eval
