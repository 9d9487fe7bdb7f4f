#pragma once

#include <vector>

#include <Eigen/Core>

namespace mjslam::slam {

/// A line seen in one scan, in the laser frame S, polar form
/// `x cos(alpha) + y sin(alpha) = rho` with rho >= 0, alpha in (-pi, pi].
struct LineObservation {
  double rho_m = 0.0;
  double alpha_rad = 0.0;
  /// Covariance of (rho, alpha), from the total-least-squares fit.
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  /// d (rho, alpha) / d b: how the fit moves when every range of its points
  /// is off by a bias b (each point shifted along its beam), to first order.
  /// (rho, 0) for a wall seen square on; less where the beams graze it.
  Eigen::Vector2d range_bias_gradient = Eigen::Vector2d::Zero();
  /// Endpoints of the seen segment in S (the first and last fitted points
  /// projected onto the line), metres; `p_SA` has the smaller beam index.
  Eigen::Vector2d p_SA = Eigen::Vector2d::Zero();
  Eigen::Vector2d p_SB = Eigen::Vector2d::Zero();
  /// Beam index range [first_beam, last_beam] of the fitted points.
  int first_beam = 0;
  int last_beam = 0;
};

/// Corner kind as seen from the sensor: concave (an inside corner of a room,
/// its vertex farther than the walls beside it) or convex (an outside corner
/// that points at the sensor).
enum class CornerKind { kConcave, kConvex };

/// A corner seen in one scan: the real vertex where two extracted lines meet,
/// in the laser frame S, in the range-bearing form of the paper's Eq. (7).
struct CornerObservation {
  double range_m = 0.0;
  double bearing_rad = 0.0;
  /// Covariance of (range, bearing), from the two lines' covariances.
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  /// d (range, bearing) / d b for a range bias b, from the two lines'.
  Eigen::Vector2d range_bias_gradient = Eigen::Vector2d::Zero();
  /// The vertex in Cartesian form in S, metres.
  Eigen::Vector2d p_SC = Eigen::Vector2d::Zero();
  CornerKind kind = CornerKind::kConcave;
  /// Indices into ScanFeatures::lines of the two lines that meet here.
  int line_a = -1;
  int line_b = -1;
};

/// Everything extracted from one scan.
struct ScanFeatures {
  std::vector<LineObservation> lines;
  std::vector<CornerObservation> corners;
};

}  // namespace mjslam::slam
