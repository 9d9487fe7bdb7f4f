#pragma once

// Helpers shared by the filter's tests: numerical Jacobians, random SPD
// matrices, and a dense reference EKF to compare the sparse one against.

#include <cmath>
#include <initializer_list>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>

#include "common/angles.h"
#include "common/rng.h"

namespace mjslam::slam::testing {

/// Central-difference Jacobian of f at x; the outputs listed in `angle_rows`
/// are differenced with wrapping.
template <int M, int N, typename F>
Eigen::Matrix<double, M, N> NumericalJacobian(F f, const Eigen::Matrix<double, N, 1>& x,
                                              std::initializer_list<int> angle_rows,
                                              double step = 1e-6) {
  Eigen::Matrix<double, M, N> J;
  for (int j = 0; j < N; ++j) {
    Eigen::Matrix<double, N, 1> plus = x;
    Eigen::Matrix<double, N, 1> minus = x;
    plus(j) += step;
    minus(j) -= step;
    Eigen::Matrix<double, M, 1> difference = f(plus) - f(minus);
    for (const int row : angle_rows) difference(row) = WrapAngle(difference(row));
    J.col(j) = difference / (2.0 * step);
  }
  return J;
}

/// A random symmetric positive definite n x n matrix with eigenvalues in
/// [min_eigenvalue, max_eigenvalue].
inline Eigen::MatrixXd RandomSpd(Rng* rng, int n, double min_eigenvalue, double max_eigenvalue) {
  Eigen::MatrixXd G(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) G(i, j) = rng->Gaussian(0.0, 1.0);
  }
  // A random orthonormal basis: the Q of a Gaussian matrix.
  Eigen::MatrixXd Q = G.householderQr().householderQ();
  Eigen::VectorXd eigenvalues(n);
  for (int i = 0; i < n; ++i) {
    eigenvalues(i) = min_eigenvalue + (max_eigenvalue - min_eigenvalue) * rng->Uniform();
  }
  Eigen::MatrixXd A = Q * eigenvalues.asDiagonal() * Q.transpose();
  return 0.5 * (A + A.transpose());
}

/// A random 2x2 SPD matrix with standard deviations around `std0`, `std1`
/// and a random correlation in (-0.8, 0.8).
inline Eigen::Matrix2d RandomCovariance2(Rng* rng, double std0, double std1) {
  const double s0 = std0 * (0.5 + rng->Uniform());
  const double s1 = std1 * (0.5 + rng->Uniform());
  const double rho = 1.6 * rng->Uniform() - 0.8;
  Eigen::Matrix2d R;
  R << s0 * s0, rho * s0 * s1, rho * s0 * s1, s1 * s1;
  return R;
}

/// Smallest eigenvalue of a symmetric matrix.
inline double MinEigenvalue(const Eigen::MatrixXd& A) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(A, Eigen::EigenvaluesOnly);
  return solver.eigenvalues().minCoeff();
}

}  // namespace mjslam::slam::testing
