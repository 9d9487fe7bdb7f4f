#pragma once

// Sequential map joining of conditionally independent submaps: what kind
// "submaps" (slam/submap_filter.h) is made of (docs/method.md, "Submaps").
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "common/map_feature.h"
#include "common/pose2.h"
#include "slam/ekf_slam.h"
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
/// f_submap - f_global = 0 (its noise the gate's linearisation residue), and
/// the submap's copies removed. New features take ids from *next_id.
JoinReport JoinSubmap(const EkfSlam& submap, const SubmapLink& link, const EkfParams& params,
                      JoinedMap* map, int* next_id);

/// The base x_B given the submap's current estimate of the shared part (as
/// JoinSubmap's first step would update it), its covariance P_B, and its
/// covariance C_BR with the submap's robot pose x_BR.
struct BaseEstimate {
  Eigen::Vector3d x_B = Eigen::Vector3d::Zero();
  Eigen::Matrix3d P_B = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d C_BR = Eigen::Matrix3d::Zero();
};
BaseEstimate BaseGivenSubmap(const EkfSlam& submap, const SubmapLink& link, const JoinedMap& map);

}  // namespace mjslam::slam
