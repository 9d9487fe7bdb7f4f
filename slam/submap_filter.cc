#include "slam/submap_filter.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <utility>

#include "slam/data_association.h"
#include "slam/ekf_filter.h"
#include "slam/observation_models.h"

namespace mjslam::slam {

SubmapFilter::SubmapFilter(const FilterSettings& settings, const Pose2& X_WR0, const Pose2& X_RS,
                           Rng rng)
    : params_(settings.slam.ekf),
      mode_(CorrectionModeFromName(settings.filter.update)),
      X_RS_(X_RS),
      rng_(std::move(rng)),
      max_features_(settings.filter.submap_max_features) {
  if (max_features_ < 1) {
    throw ParamError("submap_max_features: expected a value >= 1 (got " +
                     std::to_string(max_features_) + ")");
  }
  // The global map: the base at the initial pose, and the self-calibration's
  // prior (a submap's, as EkfSlam makes it), which the first submap shares.
  const EkfSlam prior(params_, mode_, Pose2(), X_RS_);
  const SlamState& s = prior.slam_state();
  const int nc = s.calibrated() ? SlamState::kCalibrationSize : 0;
  global_.calibration_size = nc;
  global_.mean = Eigen::VectorXd::Zero(3 + nc);
  global_.mean.head<3>() = Eigen::Vector3d(X_WR0.x, X_WR0.y, X_WR0.theta);
  global_.covariance = Eigen::MatrixXd::Zero(3 + nc, 3 + nc);
  const double sp = params_.initial_position_std_m;
  const double sh = params_.initial_heading_std_rad;
  global_.covariance.topLeftCorner<3, 3>() =
      Eigen::Vector3d(sp * sp, sp * sp, sh * sh).asDiagonal();
  if (nc > 0) {
    global_.mean.tail(nc) = s.calibration();
    global_.covariance.bottomRightCorner(nc, nc) = s.covariance().block(3, 3, nc, nc);
  }
  StartSubmap(nullptr, {});
}

void SubmapFilter::StartSubmap(const SensorRecord* record,
                               const std::vector<int>& global_features) {
  EkfParams params = params_;
  params.initial_position_std_m = 0.0;
  params.initial_heading_std_rad = 0.0;
  submap_ = std::make_unique<EkfSlam>(params, mode_, Pose2(), X_RS_,
                                      rng_.Fork("submap." + std::to_string(num_joins_)));
  // The shared part: the self-calibration and the features seen last, in B.
  link_ = LinkOf(global_, global_features);
  const int nc = global_.calibration_size;
  const Eigen::Vector3d base = global_.mean.head<3>();
  const Pose2 X_BW = Pose2(base(0), base(1), base(2)).Inverse();
  std::vector<EkfSlam::PriorFeature> features;
  for (std::size_t j = 0; j < global_features.size(); ++j) {
    const int g = global_features[j];
    EkfSlam::PriorFeature f;
    f.type = global_.types[g];
    f.params = link_.value.segment<2>(nc + 2 * j);
    if (f.type == FeatureType::kLine) {
      const Eigen::Vector2d line_W = global_.mean.segment<2>(3 + nc + 2 * g);
      f.segment = SegmentFromPoints(f.params,
                                    X_BW * PointOnLine(line_W, global_.segments[g].s_min),
                                    X_BW * PointOnLine(line_W, global_.segments[g].s_max));
      // The side seen from: the normal towards it is -side n.
      const double facing = global_.facing[g];
      if (!std::isnan(facing)) {
        f.seen_side = std::cos(facing - base(2) - f.params.y()) < 0.0 ? 1 : -1;
      }
    }
    features.push_back(f);
  }
  if (nc > 0 || !features.empty()) {
    link_.submap_ids = submap_->StartFrom(link_.value.head(nc), features, link_.P_CC);
  }
  if (record != nullptr) {
    // The reference of the next increment, with no motion of its own.
    SensorRecord reference = *record;
    reference.dt_s = 0.0;
    submap_->Step(reference, nullptr);
  }
}

StepReport SubmapFilter::Step(const SensorRecord& record, const ScanFeatures* features) {
  const bool close = features != nullptr && submap_->num_features() >= max_features_;
  std::vector<int> ids_before;
  if (close) {
    for (int k = 0; k < submap_->num_features(); ++k) ids_before.push_back(submap_->id(k));
  }
  StepReport report = submap_->Step(record, features);
  const double n = submap_->slam_state().dimension();
  report.correction_cost_n2 = report.num_updated * n * n;
  if (close) {
    // The submap ends with this scan and is joined; the next starts here,
    // sharing the features this scan saw (and the self-calibration).
    std::vector<bool> seen(submap_->num_features(), false);
    for (std::size_t i = 0; i < report.association.outcome.size(); ++i) {
      if (report.association.outcome[i] != AssociationOutcome::kMatched) continue;
      const int k = submap_->IndexOfId(ids_before[report.association.feature[i]]);
      if (k >= 0) seen[k] = true;
    }
    const int last_id =
        ids_before.empty() ? -1 : *std::max_element(ids_before.begin(), ids_before.end());
    for (int k = 0; k < submap_->num_features(); ++k) {
      if (submap_->id(k) > last_id) seen[k] = true;
    }
    const auto join_start = std::chrono::steady_clock::now();
    const JoinReport join = JoinSubmap(*submap_, link_, params_, &global_, &next_id_);
    // The join runs beside the submap's filter (the robot goes on in the
    // new submap meanwhile): its cost is not the step's.
    std::vector<int> shared;
    for (int k = 0; k < submap_->num_features(); ++k) {
      if (seen[k]) shared.push_back(join.global_index[k]);
    }
    std::sort(shared.begin(), shared.end());
    shared.erase(std::unique(shared.begin(), shared.end()), shared.end());
    ++num_joins_;
    start_times_.push_back(record.t_s);
    StartSubmap(&record, shared);
    report.beside_us = std::chrono::duration<double, std::micro>(
                           std::chrono::steady_clock::now() - join_start)
                           .count();
  }
  report.num_features = num_features();
  return report;
}

void SubmapFilter::Base(Eigen::Vector3d* x_B, Eigen::Matrix3d* P_B,
                        Eigen::Matrix3d* C_BR) const {
  const BaseEstimate base = BaseGivenSubmap(*submap_, link_, global_);
  *x_B = base.x_B;
  *P_B = base.P_B;
  *C_BR = base.C_BR;
}

Pose2 SubmapFilter::X_WR() const {
  Eigen::Vector3d x_B;
  Eigen::Matrix3d P_B;
  Eigen::Matrix3d C_BR;
  Base(&x_B, &P_B, &C_BR);
  return Pose2(x_B(0), x_B(1), x_B(2)) * submap_->X_WR();
}

Eigen::Matrix3d SubmapFilter::pose_covariance() const {
  Eigen::Vector3d x_B;
  Eigen::Matrix3d P_B;
  Eigen::Matrix3d C_BR;
  Base(&x_B, &P_B, &C_BR);
  const Pose2 X_BR = submap_->X_WR();
  const double c = std::cos(x_B(2));
  const double sn = std::sin(x_B(2));
  Eigen::Matrix3d J_base = Eigen::Matrix3d::Identity();
  J_base(0, 2) = -sn * X_BR.x - c * X_BR.y;
  J_base(1, 2) = c * X_BR.x - sn * X_BR.y;
  Eigen::Matrix3d J_pose = Eigen::Matrix3d::Identity();
  J_pose.topLeftCorner<2, 2>() << c, -sn, sn, c;
  const Eigen::Matrix3d cross = J_base * C_BR * J_pose.transpose();
  const Eigen::Matrix3d P = J_base * P_B * J_base.transpose() +
                            J_pose * submap_->pose_covariance() * J_pose.transpose() + cross +
                            cross.transpose();
  return 0.5 * (P + P.transpose());
}

std::vector<MapFeature> SubmapFilter::Map() const {
  JoinedMap joined = global_;
  int next_id = next_id_;
  JoinSubmap(*submap_, link_, params_, &joined, &next_id);
  std::vector<MapFeature> map;
  map.reserve(joined.num_features());
  for (int k = 0; k < joined.num_features(); ++k) {
    MapFeature feature;
    feature.id = joined.ids[k];
    feature.type = joined.types[k];
    const int i = 3 + joined.calibration_size + 2 * k;
    const Eigen::Vector2d params = joined.mean.segment<2>(i);
    const Eigen::Matrix2d covariance = joined.covariance.block<2, 2>(i, i);
    if (feature.type == FeatureType::kLine) {
      Eigen::Matrix2d J;
      feature.params = CanonicalLine(params, &J);
      feature.covariance = J * covariance * J.transpose();
      feature.has_segment = true;
      feature.p_WA = PointOnLine(params, joined.segments[k].s_min);
      feature.p_WB = PointOnLine(params, joined.segments[k].s_max);
    } else {
      feature.params = params;
      feature.covariance = covariance;
    }
    map.push_back(feature);
  }
  return map;
}

int SubmapFilter::num_features() const {
  return global_.num_features() + submap_->num_features();
}

}  // namespace mjslam::slam
