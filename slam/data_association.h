#pragma once

#include <vector>

#include <Eigen/Core>

namespace mjslam::slam {

/// The chi-square quantile with 2 degrees of freedom, -2 ln(1 - p), for a
/// probability p in [0, 1): 9.21 at 0.99, 5.99 at 0.95. (The 2-dof chi-square
/// CDF is 1 - exp(-x/2), so the quantile is closed form.)
double ChiSquare2Quantile(double probability);

/// What became of one observation in data association.
enum class AssociationOutcome {
  /// Matched to a map feature (inside the gate, nearest, not taken).
  kMatched,
  /// Far from every map feature of its type: initialise a new feature.
  kNew,
  /// Neither: inside the gate of a feature taken by a nearer observation, or
  /// between the gate and the new-feature threshold (the duplicate guard).
  kAmbiguous,
  /// Far from every map feature of its type, like kNew, but no observation
  /// of its scan matched a map feature: the scan cannot tell new structure
  /// from an error of the predicted pose, so it is not added
  /// (EkfParams::new_features_need_match; set by EkfSlam, never by
  /// AssociateNearestNeighbour).
  kUnanchored,
};

/// Data association of one scan.
struct Association {
  /// Per observation: the matched feature's index, -1 unless kMatched.
  std::vector<int> feature;
  /// Per observation: the outcome.
  std::vector<AssociationOutcome> outcome;
};

/// Nearest-neighbour association by Mahalanobis distance with uniqueness.
/// `d2(i, k)` is the squared Mahalanobis distance nu^T S^-1 nu of observation
/// i to map feature k; +inf (or NaN) where the pair cannot match (different
/// types, undefined prediction). Pairs with d2 < `gate` are taken in
/// increasing d2 (ties: lower i, then lower k), each observation and each map
/// feature at most once. An observation left over is kNew when d2 >=
/// `new_feature_threshold` for every feature, else kAmbiguous.
/// Precondition (checked): 0 < gate <= new_feature_threshold.
Association AssociateNearestNeighbour(const Eigen::MatrixXd& d2, double gate,
                                      double new_feature_threshold);

}  // namespace mjslam::slam
