#include "eval/pose_metrics.h"

#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "common/angles.h"

namespace mjslam::eval {
namespace {

// Smallest eigenvalue of a covariance with a NEES, relative to the largest.
constexpr double kMinEigenvalueRatio = 1e-12;
// Below this (m^2 or rad^2; a nanometre, a nanoradian) every variance is
// rounding of P = 0: the known start.
constexpr double kMinVariance = 1e-18;

}  // namespace

PoseStepMetrics EvaluatePoseStep(const Pose2& X_W_true, const Pose2& X_W_estimate,
                                 const Eigen::Matrix3d& P_pose) {
  PoseStepMetrics m;
  m.error = {X_W_estimate.x - X_W_true.x, X_W_estimate.y - X_W_true.y,
             WrapAngle(X_W_estimate.theta - X_W_true.theta)};
  for (int k = 0; k < 3; ++k) {
    const double sigma = std::sqrt(std::max(P_pose(k, k), 0.0));
    m.inside_2sigma[k] = std::abs(m.error(k)) <= 2.0 * sigma + 1e-12;
  }
  // Rank-deficient covariances (the first prediction from the known start adds
  // a rank-2 input noise to P = 0), and those that are rounding of P = 0, have
  // no NEES: their inverse is rounding.
  const Eigen::Vector3d eigenvalues =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(P_pose, Eigen::EigenvaluesOnly).eigenvalues();
  const Eigen::LLT<Eigen::Matrix3d> llt(P_pose);
  if (llt.info() == Eigen::Success && eigenvalues(2) > kMinVariance &&
      eigenvalues(0) > kMinEigenvalueRatio * eigenvalues(2)) {
    const Eigen::Vector3d whitened = llt.matrixL().solve(m.error);
    m.nees = whitened.squaredNorm();
  } else {
    m.nees = std::numeric_limits<double>::quiet_NaN();
  }
  return m;
}

PoseSummary SummarisePoseSteps(const std::vector<PoseStepMetrics>& steps) {
  PoseSummary s;
  s.num_steps = static_cast<int>(steps.size());
  double nees_sum = 0.0;
  Eigen::Vector3d squared = Eigen::Vector3d::Zero();
  for (const PoseStepMetrics& m : steps) {
    for (int k = 0; k < 3; ++k) {
      if (m.inside_2sigma[k]) s.inside_2sigma(k) += 1.0;
    }
    squared += m.error.cwiseProduct(m.error);
    if (std::isfinite(m.nees)) {
      nees_sum += m.nees;
      ++s.num_nees_steps;
    }
  }
  if (s.num_steps > 0) {
    s.inside_2sigma /= s.num_steps;
    s.rmse = (squared / s.num_steps).cwiseSqrt();
    s.final_error = steps.back().error;
  }
  s.mean_nees = s.num_nees_steps > 0 ? nees_sum / s.num_nees_steps
                                     : std::numeric_limits<double>::quiet_NaN();
  return s;
}

}  // namespace mjslam::eval
