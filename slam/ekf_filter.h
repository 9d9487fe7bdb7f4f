#pragma once

#include <vector>

#include "slam/ekf_slam.h"
#include "slam/filter.h"

namespace mjslam::slam {

/// EkfSlam as a Filter: kind "ekf" of the FilterRegistry, with
/// `update: classical` (Algorithm 1) or `update: selective` (Algorithm 2, MAX
/// and the selection policy from its settings). The paper's two filters.
class EkfFilter : public Filter {
 public:
  /// `settings.slam.ekf` (the entry's max_updates and selection_policy
  /// applied) and the mode of `settings.filter.update`; see EkfSlam's
  /// constructor for the rest. Throws ParamError for invalid settings.
  EkfFilter(const FilterSettings& settings, const Pose2& X_WR0, const Pose2& X_RS, Rng rng);

  StepReport Step(const SensorRecord& record, const ScanFeatures* features) override {
    return ekf_.Step(record, features);
  }
  Pose2 X_WR() const override { return ekf_.X_WR(); }
  Eigen::Matrix3d pose_covariance() const override { return ekf_.pose_covariance(); }
  std::vector<MapFeature> Map() const override { return ekf_.Map(); }
  int num_features() const override { return ekf_.num_features(); }

  /// The EKF itself (for tests and tools that need its whole state).
  const EkfSlam& ekf() const { return ekf_; }

 private:
  EkfSlam ekf_;
};

/// The CorrectionMode of an `update` value: "classical" or "selective".
/// Throws ParamError for any other.
CorrectionMode CorrectionModeFromName(const std::string& update);

}  // namespace mjslam::slam
