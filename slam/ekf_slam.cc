#include "slam/ekf_slam.h"

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <variant>

#include "common/angles.h"
#include "common/params.h"
#include "slam/data_association.h"
#include "slam/fast_wrap.h"
#include "slam/motion_model.h"

namespace mjslam::slam {
namespace {

const EkfParams& Validated(const EkfParams& params) {
  ThrowIfProblems(params.Validate(), "slam.ekf");
  return params;
}

bool IsFinite(const Pose2& pose) {
  return std::isfinite(pose.x) && std::isfinite(pose.y) && std::isfinite(pose.theta);
}

std::string PoseText(const Pose2& pose) {
  return "(" + ValueText(pose.x) + ", " + ValueText(pose.y) + ", " + ValueText(pose.theta) + ")";
}

std::string MatrixText(const Eigen::Matrix2d& m) {
  return "[" + ValueText(m(0, 0)) + ", " + ValueText(m(0, 1)) + "; " + ValueText(m(1, 0)) +
         ", " + ValueText(m(1, 1)) + "]";
}

// Throws SlamInputError for `what` unless R is finite, symmetric and positive
// definite; returns it exactly symmetric.
Eigen::Matrix2d CheckedCovariance(const Eigen::Matrix2d& R, const std::string& what) {
  const bool finite = R.allFinite();
  const double asymmetry = std::abs(R(0, 1) - R(1, 0));
  const double scale = std::max(std::abs(R(0, 0)), std::abs(R(1, 1)));
  const Eigen::Matrix2d symmetric = 0.5 * (R + R.transpose());
  const double det = symmetric(0, 0) * symmetric(1, 1) - symmetric(0, 1) * symmetric(1, 0);
  if (!finite || asymmetry > 1e-9 * scale || !(symmetric(0, 0) > 0.0) || !(det > 0.0)) {
    throw SlamInputError("EkfSlam::Step: " + what +
                         ": expected a finite, symmetric, positive definite matrix (got " +
                         MatrixText(R) + ")");
  }
  return symmetric;
}

void RequireFinite(double value, const std::string& what) {
  if (!std::isfinite(value)) {
    throw SlamInputError("EkfSlam::Step: " + what + ": expected a finite value (got " +
                         ValueText(value) + ")");
  }
}

// The prior standard deviations of the self-calibration entries, in the
// state's order; empty when self-calibration is off.
Eigen::VectorXd CalibrationStd(const SelfCalibrationParams& calibration) {
  if (!calibration.Enabled()) return Eigen::VectorXd();
  Eigen::VectorXd std(SlamState::kCalibrationSize);
  std << calibration.distance_scale_std, calibration.heading_scale_std,
      calibration.heading_per_m_std_rad, calibration.range_bias_std_m, calibration.range_scale_std;
  return std;
}

}  // namespace

EkfSlam::EkfSlam(const EkfParams& params, CorrectionMode mode, const Pose2& X_WR0,
                 const Pose2& X_RS, Rng rng)
    : params_(Validated(params)),
      mode_(mode),
      integration_(MotionIntegrationFromName(IntegrationOf(params.process_model))),
      policy_(SelectionPolicyFromName(params.selection_policy)),
      rng_(std::move(rng)),
      state_(Eigen::Vector3d(X_WR0.x, X_WR0.y, X_WR0.theta),
             Eigen::Vector3d(params.initial_position_std_m * params.initial_position_std_m,
                             params.initial_position_std_m * params.initial_position_std_m,
                             params.initial_heading_std_rad * params.initial_heading_std_rad)
                 .asDiagonal(),
             X_RS, JacobianPointFromName(params.jacobians), CalibrationStd(params.self_calibration)),
      gate_(ChiSquare2Quantile(params.gate_probability)),
      new_feature_threshold_(ChiSquare2Quantile(params.new_feature_probability)) {
  if (!IsFinite(X_WR0)) {
    throw SlamInputError("EkfSlam: X_WR0: expected a finite pose (got " + PoseText(X_WR0) + ")");
  }
  if (!IsFinite(X_RS)) {
    throw SlamInputError("EkfSlam: X_RS: expected a finite pose (got " + PoseText(X_RS) + ")");
  }
}

Pose2 EkfSlam::X_WR() const {
  const Eigen::Vector3d pose = state_.pose();
  return Pose2(pose.x(), pose.y(), pose.z());
}

std::vector<EkfSlam::Observation> EkfSlam::CollectObservations(
    const ScanFeatures& features) const {
  std::vector<Observation> observations;
  observations.reserve(features.lines.size() + features.corners.size());

  // Lines, canonical, with the model-error noise added.
  const Eigen::Matrix2d extra_line =
      Eigen::Vector2d(params_.extra_line_rho_std_m * params_.extra_line_rho_std_m,
                      params_.extra_line_alpha_std_rad * params_.extra_line_alpha_std_rad)
          .asDiagonal();
  for (std::size_t i = 0; i < features.lines.size(); ++i) {
    const LineObservation& line = features.lines[i];
    const std::string what = "features.lines[" + std::to_string(i) + "]";
    RequireFinite(line.rho_m, what + ".rho_m");
    RequireFinite(line.alpha_rad, what + ".alpha_rad");
    if (!line.p_SA.allFinite() || !line.p_SB.allFinite()) {
      throw SlamInputError("EkfSlam::Step: " + what + ".p_SA/p_SB: expected finite points");
    }
    Eigen::Matrix2d J;
    Observation observation;
    observation.type = FeatureType::kLine;
    observation.z = CanonicalLine(Eigen::Vector2d(line.rho_m, line.alpha_rad), &J);
    observation.R = J * CheckedCovariance(line.covariance + extra_line, what + ".covariance") *
                    J.transpose();
    observation.range_bias_gradient = J * line.range_bias_gradient;
    observation.p_SA = line.p_SA;
    observation.p_SB = line.p_SB;
    observations.push_back(observation);
  }

  // Corners, likewise.
  const Eigen::Matrix2d extra_corner =
      Eigen::Vector2d(params_.extra_corner_range_std_m * params_.extra_corner_range_std_m,
                      params_.extra_corner_bearing_std_rad * params_.extra_corner_bearing_std_rad)
          .asDiagonal();
  for (std::size_t i = 0; i < features.corners.size(); ++i) {
    const CornerObservation& corner = features.corners[i];
    const std::string what = "features.corners[" + std::to_string(i) + "]";
    RequireFinite(corner.bearing_rad, what + ".bearing_rad");
    if (!(corner.range_m > 0.0) || !std::isfinite(corner.range_m)) {
      throw SlamInputError("EkfSlam::Step: " + what + ".range_m: expected a finite value > 0 (got " +
                           ValueText(corner.range_m) + ")");
    }
    Observation observation;
    observation.type = FeatureType::kCorner;
    observation.z = Eigen::Vector2d(corner.range_m, WrapAngleFast(corner.bearing_rad));
    observation.R = CheckedCovariance(corner.covariance + extra_corner, what + ".covariance");
    observation.range_bias_gradient = corner.range_bias_gradient;
    observation.p_SA = corner.p_SC;
    observation.p_SB = corner.p_SC;
    observations.push_back(observation);
  }
  return observations;
}

Eigen::MatrixXd EkfSlam::MahalanobisDistances(const std::vector<Observation>& observations) const {
  const int num_observations = static_cast<int>(observations.size());
  Eigen::MatrixXd d2 = Eigen::MatrixXd::Constant(num_observations, state_.num_features(),
                                                 std::numeric_limits<double>::infinity());
  const Pose2 X_WS = X_WR() * state_.X_RS();
  for (int k = 0; k < state_.num_features(); ++k) {
    // The prediction and H P H^T depend on the feature only: once per feature.
    const SlamState::Measurement m = state_.Measure(k);
    if (!m.valid) continue;
    for (int i = 0; i < num_observations; ++i) {
      const Observation& observation = observations[i];
      if (observation.type != state_.feature_type(k)) continue;
      if (observation.type == FeatureType::kLine && !SegmentsMeet(k, observation, X_WS)) continue;
      // A line's prediction in the observation's polar form.
      SlamState::Measurement mo = m;
      if (observation.type == FeatureType::kLine) {
        // A wall's face is seen from its front only: with the sensor
        // clearly on the other side of the line than when the feature was
        // made, the observation is of another face (the back of a thin
        // wall, 0.15 m away), not of this one (docs/method.md, departure 5).
        if (params_.gate_line_side && info_[k].seen_side != 0) {
          const double side = SensorSideOfLine(k);
          const double margin = 3.0 * std::sqrt(mo.HPHt(0, 0) + observation.R(0, 0));
          if (side * info_[k].seen_side < 0.0 && std::abs(side) > margin) continue;
        }
      }
      state_.ToObservation(observation.type, observation.z, observation.range_bias_gradient, &mo);
      const Eigen::Vector2d nu = Innovation(observation.z, mo.h);
      const Eigen::Matrix2d S = mo.HPHt + observation.R;
      // nu^T S^-1 nu with the 2x2 inverse written out.
      const double det = S(0, 0) * S(1, 1) - S(0, 1) * S(1, 0);
      d2(i, k) = (S(1, 1) * nu.x() * nu.x() - (S(0, 1) + S(1, 0)) * nu.x() * nu.y() +
                  S(0, 0) * nu.y() * nu.y()) /
                 det;
    }
  }
  return d2;
}

bool EkfSlam::SegmentsMeet(int k, const Observation& observation, const Pose2& X_WS) const {
  const double max_gap = params_.line_match_max_gap_m;
  if (max_gap <= 0.0) return true;
  const LineSegment seen = SegmentFromPoints(state_.feature(k), X_WS * observation.p_SA,
                                             X_WS * observation.p_SB);
  const LineSegment& known = info_[k].segment;
  return SegmentGap(seen, known) <= max_gap;
}

double EkfSlam::SensorSideOfLine(int k) const {
  const Pose2 X_WS = X_WR() * state_.X_RS();
  const Eigen::Vector2d line = state_.feature(k);
  return line.x() - X_WS.x * std::cos(line.y()) - X_WS.y * std::sin(line.y());
}

void EkfSlam::GrowSegment(int k, const Observation& observation) {
  const Pose2 X_WS = X_WR() * state_.X_RS();
  info_[k].segment = ExtendSegment(info_[k].segment, state_.feature(k), X_WS * observation.p_SA,
                                   X_WS * observation.p_SB);
}

bool EkfSlam::SameWall(int a, int b) const {
  if (state_.feature_type(a) != FeatureType::kLine || state_.feature_type(b) != FeatureType::kLine) {
    return false;
  }
  const int side_a = info_[a].seen_side;
  const int side_b = info_[b].seen_side;
  const Eigen::Vector2d f_a = state_.feature(a);
  const Eigen::Vector2d f_b = state_.feature(b);
  // Seen from the same side: the normals towards the sensor, -side n, agree.
  const double normals = std::cos(f_a.y() - f_b.y());
  if (side_a * side_b * normals <= 0.0) return false;
  // Both ends of an overlap of at least min_overlap within `distance` of
  // line b bound the angle between the lines: |sin| <= 2 distance /
  // min_overlap. A cheaper test, implied by the ones below.
  const double max_sin = 2.0 * params_.duplicate_line_distance_m / params_.duplicate_line_min_overlap_m;
  if (max_sin < 1.0 && 1.0 - normals * normals > max_sin * max_sin) return false;
  // The overlap of the seen segments, along line a.
  const LineSegment& seg_a = info_[a].segment;
  const LineSegment seg_b = SegmentFromPoints(f_a, PointOnLine(f_b, info_[b].segment.s_min),
                                              PointOnLine(f_b, info_[b].segment.s_max));
  const double s_from = std::max(seg_a.s_min, seg_b.s_min);
  const double s_to = std::min(seg_a.s_max, seg_b.s_max);
  if (s_to - s_from < params_.duplicate_line_min_overlap_m) return false;
  // Line b's distance from line a's points at both ends of the overlap.
  const Eigen::Vector2d n_b(std::cos(f_b.y()), std::sin(f_b.y()));
  for (const double s : {s_from, s_to}) {
    if (std::abs(n_b.dot(PointOnLine(f_a, s)) - f_b.x()) > params_.duplicate_line_distance_m) {
      return false;
    }
  }
  return true;
}

int EkfSlam::RemoveDuplicateLines(std::vector<int> touched) {
  const auto det = [&](int k) {
    const Eigen::Matrix2d P = state_.feature_covariance(k);
    return P(0, 0) * P(1, 1) - P(0, 1) * P(1, 0);
  };
  int removed = 0;
  for (std::size_t t = 0; t < touched.size(); ++t) {
    // touched[t] follows its line as removals move the indices; -1 once the
    // line itself was removed.
    for (int b = 0; touched[t] >= 0 && b < state_.num_features(); ++b) {
      const int a = touched[t];
      if (b == a || !SameWall(a, b)) continue;
      const int keep = det(a) <= det(b) ? a : b;
      const int drop = keep == a ? b : a;
      const Eigen::Vector2d f_drop = state_.feature(drop);
      info_[keep].segment =
          ExtendSegment(info_[keep].segment, state_.feature(keep),
                        PointOnLine(f_drop, info_[drop].segment.s_min),
                        PointOnLine(f_drop, info_[drop].segment.s_max));
      state_.RemoveFeature(drop);
      info_.erase(info_.begin() + drop);
      ++removed;
      for (int& k : touched) {
        if (k == drop) {
          k = -1;
        } else if (k > drop) {
          --k;
        }
      }
      // Line a stays: look again at the line now at index b.
      if (drop == b) --b;
    }
  }
  return removed;
}

MotionInput EkfSlam::CheckedMotionInput(const SensorRecord& record) const {
  if (!std::isfinite(record.dt_s) || record.dt_s < 0.0) {
    throw SlamInputError("EkfSlam::Step: record.dt_s: expected a finite value >= 0 (got " +
                         ValueText(record.dt_s) + ")");
  }
  // The input and its noise, by the process model's kind.
  MotionInput input;
  if (const auto* odometry = std::get_if<OdometryProcessModel>(&params_.process_model)) {
    if (!IsFinite(record.X_OR)) {
      throw SlamInputError("EkfSlam::Step: record.X_OR: expected a finite pose (got " +
                           PoseText(record.X_OR) + ")");
    }
    // The first record is the reference of the odometry increments.
    const Pose2& X_OR_previous = has_odometry_ ? X_OR_previous_ : record.X_OR;
    input = OdometryInput(X_OR_previous, record.X_OR, params_.control_point_offset_m,
                          odometry->noise);
  } else {
    const CommandProcessModel& command = std::get<CommandProcessModel>(params_.process_model);
    RequireFinite(record.command.v_mps, "record.command.v_mps");
    RequireFinite(record.command.w_radps, "record.command.w_radps");
    input = CommandInput(record.command, record.dt_s, command.noise, previous_command_);
  }
  // The sideways motion either kind adds.
  const LateralMotionParams& lateral = LateralOf(params_.process_model);
  const double turn_slip_std = lateral.slip_std_m_per_rad * std::abs(input.increment.y());
  const double roll_slip_std = lateral.slip_std_m_per_sqrt_m;
  input.lateral_variance_m2 =
      turn_slip_std * turn_slip_std + roll_slip_std * roll_slip_std * std::abs(input.increment.x());
  if (record.dt_s > 0.0) input.skid_per_m_rad = lateral.skid_s / record.dt_s;
  input.integration = integration_;
  input.axle_track_m = params_.axle_track_m;
  const double drift = params_.self_calibration.wheel_slip_drift_std_per_sqrt_m;
  input.wheel_slip_drift_per_m = drift * drift;
  // The derivatives by the odometry's errors (q_d, q_th, k) are taken at the
  // commanded increment, which carries none of the odometry's noise: taken at
  // the odometry's own increment, its noise would bias the scales towards
  // less motion (docs/method.md, "Self-calibration").
  input.calibration_jacobian_increment =
      Eigen::Vector2d(record.command.v_mps * record.dt_s, record.command.w_radps * record.dt_s);
  return input;
}

void EkfSlam::Predict(const SensorRecord& record, const MotionInput& input) {
  if (PredictsFromOdometry(params_.process_model)) {
    X_OR_previous_ = record.X_OR;
    has_odometry_ = true;
  }
  previous_command_ = record.command;
  state_.Predict(input, params_.control_point_offset_m);
}

void EkfSlam::HoldBackUnanchored(Association* association) const {
  if (state_.num_features() == 0) return;
  for (const AssociationOutcome outcome : association->outcome) {
    if (outcome == AssociationOutcome::kMatched) return;
  }
  for (AssociationOutcome& outcome : association->outcome) {
    if (outcome == AssociationOutcome::kNew) outcome = AssociationOutcome::kUnanchored;
  }
}

std::vector<MatchedObservation> EkfSlam::SelectMatches(
    const Association& association, const std::vector<Observation>& observations,
    const ScanFeatures& features, StepReport* report, std::vector<int>* matched_observation) const {
  // Observations are the lines, then the corners (CollectObservations).
  const int num_lines = static_cast<int>(features.lines.size());
  auto line_matched = [&](int line) {
    return line >= 0 && line < num_lines &&
           association.outcome[line] == AssociationOutcome::kMatched;
  };
  std::vector<MatchedObservation> matched;
  for (int i = 0; i < report->num_observed; ++i) {
    if (association.outcome[i] == AssociationOutcome::kMatched) {
      if (i >= num_lines && !params_.correct_corners_of_matched_lines) {
        // The corner repeats what its two lines say when both correct too.
        const CornerObservation& corner = features.corners[i - num_lines];
        if (line_matched(corner.line_a) && line_matched(corner.line_b)) {
          ++report->num_redundant_corners;
          continue;
        }
      }
      matched.push_back({association.feature[i], observations[i].z, observations[i].R,
                         observations[i].range_bias_gradient});
      matched_observation->push_back(i);
    } else if (association.outcome[i] == AssociationOutcome::kNew) {
      ++report->num_new;
    } else if (association.outcome[i] == AssociationOutcome::kUnanchored) {
      ++report->num_unanchored;
    } else {
      ++report->num_ambiguous;
    }
  }
  report->num_matched = static_cast<int>(matched.size()) + report->num_redundant_corners;
  return matched;
}

void EkfSlam::AddNewFeatures(const Association& association,
                             const std::vector<Observation>& observations,
                             const ScanFeatures& features, StepReport* report) {
  // The lines come first, so a new corner can be placed where its lines are.
  const int num_lines = static_cast<int>(features.lines.size());
  std::vector<int> line_feature(num_lines, -1);
  for (int i = 0; i < num_lines; ++i) {
    if (association.outcome[i] == AssociationOutcome::kMatched) line_feature[i] = association.feature[i];
  }
  for (int i = 0; i < report->num_observed; ++i) {
    if (association.outcome[i] != AssociationOutcome::kNew) continue;
    const Observation& observation = observations[i];
    int k = -1;
    if (i >= num_lines && params_.corners_from_map_lines) {
      const CornerObservation& corner = features.corners[i - num_lines];
      auto map_line = [&](int line) { return line >= 0 && line < num_lines ? line_feature[line] : -1; };
      const int a = map_line(corner.line_a);
      const int b = map_line(corner.line_b);
      if (a >= 0 && b >= 0 && a != b) {
        k = state_.AddLineIntersection(a, b);
        ++report->num_corners_from_lines;
      }
    }
    if (k < 0) {
      k = state_.AddFeature(observation.type, observation.z, observation.R,
                            observation.range_bias_gradient);
    }
    if (i < num_lines) line_feature[i] = k;
    info_.push_back({next_id_++, LineSegment{}});
    if (observation.type == FeatureType::kLine) {
      info_[k].seen_side = SensorSideOfLine(k) < 0.0 ? -1 : 1;
      const Pose2 X_WS = X_WR() * state_.X_RS();
      info_[k].segment = SegmentFromPoints(state_.feature(k), X_WS * observation.p_SA,
                                           X_WS * observation.p_SB);
    }
  }
}

StepReport EkfSlam::Step(const SensorRecord& record, const ScanFeatures* features) {
  // Everything is checked before anything changes.
  const MotionInput input = CheckedMotionInput(record);
  std::vector<Observation> observations;
  if (features != nullptr) observations = CollectObservations(*features);

  // Prediction, Eqs. (1)-(2) with (6).
  Predict(record, input);

  StepReport report;
  if (features == nullptr) {
    report.num_features = state_.num_features();
    return report;
  }
  report.num_observed = static_cast<int>(observations.size());

  // Data association against the predicted map, and the matches that correct.
  const Eigen::MatrixXd d2 = MahalanobisDistances(observations);
  Association association = AssociateNearestNeighbour(d2, gate_, new_feature_threshold_);
  if (params_.new_features_need_match) HoldBackUnanchored(&association);
  report.nearest_nis.assign(report.num_observed, std::numeric_limits<double>::infinity());
  for (int i = 0; i < report.num_observed; ++i) {
    if (association.outcome[i] == AssociationOutcome::kMatched) {
      report.nis_sum += d2(i, association.feature[i]);
    }
    for (int k = 0; k < d2.cols(); ++k) {
      if (d2(i, k) < report.nearest_nis[i]) report.nearest_nis[i] = d2(i, k);
    }
  }
  report.association = association;
  std::vector<int> matched_observation;
  const std::vector<MatchedObservation> matched =
      SelectMatches(association, observations, *features, &report, &matched_observation);

  // Correction: Algorithm 1 or 2.
  if (mode_ == CorrectionMode::kClassical) {
    report.num_updated = CorrectClassical(&state_, matched);
  } else {
    report.num_updated =
        static_cast<int>(CorrectSelective(&state_, matched, params_.max_updates, policy_, &rng_).size());
  }

  // Secondary map: every matched line's segment grows with what was seen,
  // placed with the corrected pose.
  for (std::size_t m = 0; m < matched.size(); ++m) {
    const Observation& observation = observations[matched_observation[m]];
    if (observation.type == FeatureType::kLine) GrowSegment(matched[m].feature, observation);
  }

  // New features from the corrected pose (inverse observation models).
  const int num_before_new = state_.num_features();
  AddNewFeatures(association, observations, *features, &report);

  // A wall now mapped twice keeps its more certain line.
  if (params_.duplicate_line_distance_m > 0.0) {
    std::vector<int> touched;
    for (const MatchedObservation& match : matched) {
      if (state_.feature_type(match.feature) == FeatureType::kLine) touched.push_back(match.feature);
    }
    for (int k = num_before_new; k < state_.num_features(); ++k) touched.push_back(k);
    RemoveDuplicateLines(std::move(touched));
  }
  report.num_features = state_.num_features();
  return report;
}

std::vector<int> EkfSlam::StartFrom(const Eigen::VectorXd& calibration,
                                    const std::vector<PriorFeature>& features,
                                    const Eigen::MatrixXd& covariance) {
  std::vector<FeatureType> types;
  Eigen::VectorXd means(2 * features.size());
  for (std::size_t k = 0; k < features.size(); ++k) {
    types.push_back(features[k].type);
    means.segment<2>(2 * k) = features[k].params;
  }
  state_.StartFrom(calibration, types, means, covariance);
  std::vector<int> ids;
  for (const PriorFeature& feature : features) {
    ids.push_back(next_id_);
    info_.push_back({next_id_++, feature.segment, feature.seen_side});
  }
  return ids;
}

int EkfSlam::IndexOfId(int id) const {
  for (int k = 0; k < num_features(); ++k) {
    if (info_[k].id == id) return k;
  }
  return -1;
}

std::vector<MapFeature> EkfSlam::Map() const {
  std::vector<MapFeature> map;
  map.reserve(state_.num_features());
  for (int k = 0; k < state_.num_features(); ++k) {
    MapFeature feature;
    feature.id = info_[k].id;
    feature.type = state_.feature_type(k);
    const Eigen::Vector2d params = state_.feature(k);
    const Eigen::Matrix2d covariance = state_.feature_covariance(k);
    if (feature.type == FeatureType::kLine) {
      // Canonical form; the segment's points do not depend on it.
      Eigen::Matrix2d J;
      feature.params = CanonicalLine(params, &J);
      feature.covariance = J * covariance * J.transpose();
      feature.has_segment = true;
      feature.p_WA = PointOnLine(params, info_[k].segment.s_min);
      feature.p_WB = PointOnLine(params, info_[k].segment.s_max);
    } else {
      feature.params = params;
      feature.covariance = covariance;
    }
    map.push_back(feature);
  }
  return map;
}

}  // namespace mjslam::slam
