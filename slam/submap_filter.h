#pragma once

// Kind "submaps" of the FilterRegistry: EKF-SLAM in bounded submaps joined
// into a global map (docs/method.md, "Submaps").
#include <memory>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "common/map_feature.h"
#include "common/pose2.h"
#include "common/rng.h"
#include "slam/ekf_slam.h"
#include "slam/filter.h"
#include "slam/secondary_map.h"

namespace mjslam::slam {

/// The global map of sequential map joining: the pose of the current
/// submap's base frame B in W, the self-calibration entries (if any) at the
/// base, and the features in W, with their full covariance. State
/// [x_B, y_B, th_B, c, f_1, ..., f_L], feature k at 3 + nc + 2k; lines
/// (r, al) in canonical form when joined.
struct JoinedMap {
  /// nc: 0, or SlamState::kCalibrationSize with self-calibration.
  int calibration_size = 0;
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(3);
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(3, 3);
  std::vector<FeatureType> types;
  std::vector<int> ids;
  /// Lines: the seen segment along the line's current estimate.
  std::vector<LineSegment> segments;
  /// Lines: the direction (radians in W) of the line's normal that points
  /// to the side it was seen from; NaN when not known, and for corners.
  std::vector<double> facing;

  int num_features() const { return static_cast<int>(types.size()); }
};

/// What a submap shares with the global map it started from (conditionally
/// independent submaps): C, the self-calibration c0 (if any) and the
/// features the last scan of the submap before saw, expressed in the base B,
/// C = g(global map) with Jacobian G, at the global map as it was when the
/// submap started; the submap's own copies of those features.
struct SubmapLink {
  /// The shared features' indices in the global map, and their ids in the
  /// submap (in the same order).
  std::vector<int> global_features;
  std::vector<int> submap_ids;
  /// C = [c, f_B...] (nc + 2 per feature), G by rows (sparse: state index,
  /// value), G P and G P G^T (= P_CC, the submap's prior over C).
  Eigen::VectorXd value;
  std::vector<std::vector<std::pair<int, double>>> G;
  Eigen::MatrixXd GP;
  Eigen::MatrixXd P_CC;
  /// A cache: the pseudo-inverse of P_CC over the rows the submap still
  /// estimates (a shared line it removed as a duplicate drops out).
  mutable std::vector<int> pseudo_inverse_rows;
  mutable Eigen::MatrixXd pseudo_inverse;
};

/// The link of a submap that starts at `map`'s base sharing the
/// self-calibration and the global features `global_features`.
SubmapLink LinkOf(const JoinedMap& map, const std::vector<int>& global_features);

/// What one join did.
struct JoinReport {
  /// The submap's features that matched a feature of the global map (and
  /// were fused with it), and those added as new features.
  int num_matched = 0;
  int num_new = 0;
  /// The joined state's size n when the matches were fused (their cost is
  /// num_matched n^2 in the cost model).
  int state_size = 0;
  /// Each submap feature's index in the joined map.
  std::vector<int> global_index;
};

/// Sequential map joining (Tardos, Neira, Newman and Leonard, IJRR 21(4),
/// 2002) of conditionally independent submaps (Pinies and Tardos, IEEE
/// T-RO 24(5), 2008; docs/method.md, "Submaps"). `submap` is an EKF-SLAM
/// whose W is the base frame B of `map`, started at B with zero covariance
/// and with the shared part C of `link` as its prior, so that it is
/// independent of `map` given C. The join: the submap's estimate of C
/// updates `map` through its correlations with C; the submap's robot pose
/// and own features are carried to W through x_B (first order, the cross
/// terms through x_B and C), the pose becoming the new base and the current
/// self-calibration the map's; then each own feature is matched to the
/// global feature nearest in the Mahalanobis distance of their difference
/// (the gate of `params.gate_probability`, the same type, a line seen from
/// the same side with seen segments within `params.line_match_max_gap_m`; a
/// global feature may take several, a wall the submap mapped in pieces), the
/// pairs are fused by one batch EKF update with the identity constraint
/// f_submap - f_global = 0, and the submap's copies removed. New features
/// take ids from *next_id.
JoinReport JoinSubmap(const EkfSlam& submap, const SubmapLink& link, const EkfParams& params,
                      JoinedMap* map, int* next_id);

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
  bool predicts_from_odometry() const override { return odometry_; }
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
  bool odometry_;
  int max_features_;
  JoinedMap global_;
  std::unique_ptr<EkfSlam> submap_;
  SubmapLink link_;
  int num_joins_ = 0;
  std::vector<double> start_times_;
  int next_id_ = 0;
};

}  // namespace mjslam::slam
