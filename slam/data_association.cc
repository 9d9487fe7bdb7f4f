#include "slam/data_association.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "common/check.h"

namespace mjslam::slam {

double ChiSquare2Quantile(double probability) {
  MJSLAM_CHECK(probability >= 0.0 && probability < 1.0);
  return -2.0 * std::log1p(-probability);
}

Association AssociateNearestNeighbour(const Eigen::MatrixXd& d2, double gate,
                                      double new_feature_threshold) {
  MJSLAM_CHECK(gate > 0.0 && gate <= new_feature_threshold);
  const int num_observations = static_cast<int>(d2.rows());
  const int num_features = static_cast<int>(d2.cols());

  // Every pair inside the gate (NaN fails the comparison, so never enters).
  std::vector<std::tuple<double, int, int>> pairs;
  for (int k = 0; k < num_features; ++k) {
    for (int i = 0; i < num_observations; ++i) {
      if (d2(i, k) < gate) pairs.emplace_back(d2(i, k), i, k);
    }
  }
  std::sort(pairs.begin(), pairs.end());

  // Greedy nearest neighbour: the closest pairs first, each side once.
  Association result;
  result.feature.assign(num_observations, -1);
  result.outcome.assign(num_observations, AssociationOutcome::kAmbiguous);
  std::vector<bool> feature_taken(num_features, false);
  for (const auto& [distance, i, k] : pairs) {
    if (result.feature[i] >= 0 || feature_taken[k]) continue;
    result.feature[i] = k;
    result.outcome[i] = AssociationOutcome::kMatched;
    feature_taken[k] = true;
  }

  // Left-over observations: new only if far from every feature (the
  // duplicate guard keeps near misses and lost contests out of the map).
  for (int i = 0; i < num_observations; ++i) {
    if (result.feature[i] >= 0) continue;
    bool far_from_all = true;
    for (int k = 0; k < num_features; ++k) {
      if (!(d2(i, k) >= new_feature_threshold) && !std::isnan(d2(i, k))) {
        far_from_all = false;
        break;
      }
    }
    if (far_from_all) result.outcome[i] = AssociationOutcome::kNew;
  }
  return result;
}

}  // namespace mjslam::slam
