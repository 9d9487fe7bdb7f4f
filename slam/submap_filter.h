#pragma once

// Kind "submaps" of the FilterRegistry: EKF-SLAM in bounded submaps joined
// into a global map (docs/method.md, "Submaps").
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "common/map_feature.h"
#include "common/pose2.h"
#include "common/rng.h"
#include "slam/ekf_slam.h"
#include "slam/filter.h"
#include "slam/submap_join.h"

namespace mjslam::slam {

/// Kind "submaps": the paper's EKF-SLAM (`update: classical` or
/// `selective`, as kind ekf) run in a local submap that starts empty at the
/// robot's pose, closed when it holds `submap_max_features` features and
/// joined into the global map by JoinSubmap; the next submap starts where
/// the last ended. Every correction updates the submap's state only, so a
/// step costs O(submap size^2) whatever the size of the global map; a join
/// costs O(global size^2) per matched feature.
class SubmapFilter : public Filter {
 public:
  /// `settings.slam.ekf` (the entry's max_updates and selection_policy
  /// applied) for every submap; the global map starts with x_B = X_WR0 and
  /// the initial pose covariance of `settings.slam.ekf`. Throws ParamError
  /// for invalid settings.
  SubmapFilter(const FilterSettings& settings, const Pose2& X_WR0, const Pose2& X_RS, Rng rng);

  StepReport Step(const SensorRecord& record, const ScanFeatures* features) override;
  /// X_WB * X_BR: the base's pose in W composed with the submap's estimate.
  Pose2 X_WR() const override;
  /// J_B P_B J_B^T + J_R P_R J_R^T (the submap is independent of the base).
  Eigen::Matrix3d pose_covariance() const override;
  /// The global map with the current submap joined into it (a copy; the
  /// filter is unchanged), lines with their seen segments. O(n^2).
  std::vector<MapFeature> Map() const override;
  /// Global features plus the current submap's (some of which a join would
  /// fuse with global ones).
  int num_features() const override;
  std::vector<double> SubmapStartTimes() const override { return start_times_; }

  /// The global map as joined so far (without the current submap).
  const JoinedMap& global_map() const { return global_; }
  /// The current submap.
  const EkfSlam& submap() const { return *submap_; }
  /// What the current submap shares with the global map.
  const SubmapLink& link() const { return link_; }
  /// The number of submaps joined so far.
  int num_joins() const { return num_joins_; }

 private:
  // A new submap at the base of global_, sharing its self-calibration and
  // the features `global_features` (link_), primed with `record` (if any)
  // as its odometry and command reference (its first step predicts no
  // motion).
  void StartSubmap(const SensorRecord* record, const std::vector<int>& global_features);
  // The base x_B given the submap's estimate of the shared calibration,
  // its covariance, and its covariance with the submap's pose x_BR.
  void Base(Eigen::Vector3d* x_B, Eigen::Matrix3d* P_B, Eigen::Matrix3d* C_BR) const;

  EkfParams params_;
  CorrectionMode mode_;
  Pose2 X_RS_;
  Rng rng_;
  int max_features_;
  JoinedMap global_;
  std::unique_ptr<EkfSlam> submap_;
  SubmapLink link_;
  int num_joins_ = 0;
  std::vector<double> start_times_;
  int next_id_ = 0;
};

}  // namespace mjslam::slam
