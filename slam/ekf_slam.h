#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/map_feature.h"
#include "common/pose2.h"
#include "common/records.h"
#include "common/rng.h"
#include "slam/corrections.h"
#include "slam/data_association.h"
#include "slam/motion_model.h"
#include "slam/observations.h"
#include "slam/secondary_map.h"
#include "slam/slam_params.h"
#include "slam/slam_state.h"

namespace mjslam::slam {

/// Which correction stage the filter runs.
enum class CorrectionMode {
  /// Algorithm 1: every matched observation, sequentially.
  kClassical,
  /// Algorithm 2: the `max_updates` most informative matched observations
  /// (or those of another EkfParams::selection_policy, for ablations).
  kSelective,
};

/// What one Step did (expected outcomes are data, not errors).
struct StepReport {
  /// Map features after the step.
  int num_features = 0;
  /// Observations given (lines + corners); 0 for a prediction-only step.
  int num_observed = 0;
  /// Observations associated with a map feature.
  int num_matched = 0;
  /// Matched corners left out of the correction because both their lines
  /// matched too (EkfParams::correct_corners_of_matched_lines).
  int num_redundant_corners = 0;
  /// Corrections applied: num_matched - num_redundant_corners (classical) or
  /// at most max_updates of those (selective).
  int num_updated = 0;
  /// Observations that became new features.
  int num_new = 0;
  /// New corners placed where their two map lines meet, not from their own
  /// observation (EkfParams::corners_from_map_lines); counted in num_new.
  int num_corners_from_lines = 0;
  /// Observations neither matched nor added (lost a contest for a feature,
  /// or between the gate and the new-feature threshold).
  int num_ambiguous = 0;
  /// Observations far from every feature that were not added because no
  /// observation of the scan matched (EkfParams::new_features_need_match);
  /// not counted in num_ambiguous.
  int num_unanchored = 0;
  /// Sum of the NIS nu^T S^-1 nu of the matched observations (num_matched of
  /// them), each against its feature in the predicted state, before any
  /// correction: the input of InnovationCheck.
  double nis_sum = 0.0;
  /// The corrections' cost for ControlParams' cost model: the sum over the
  /// step's corrections of n^2, n the size of the state each one updated.
  /// Negative (EkfSlam): num_updated (3 + 2 num_features)^2.
  double correction_cost_n2 = -1.0;
  /// Microseconds of the step spent on work that runs beside the filter (a
  /// submap's join): left out of its measured processing time.
  double beside_us = 0.0;
  /// What became of each observation (lines first, then corners, as the
  /// features were extracted), for diagnostics: its outcome and matched
  /// feature (an index into the map before this step's duplicate lines were
  /// removed), and `nearest_nis`, the smallest NIS to any map feature of its
  /// type before the correction (+inf: none).
  Association association;
  std::vector<double> nearest_nis;
};

/// Bad data given to the filter (a non-finite record, a negative dt, an
/// observation with a non-finite value or a covariance that is not positive
/// definite). The message names the field and value.
class SlamInputError : public std::runtime_error {
 public:
  explicit SlamInputError(const std::string& message) : std::runtime_error(message) {}
};

/// Sequential EKF-SLAM over lines and corners, as in Auat Cheein et al.,
/// Robotica 29(2), 2011 (slam/README.md, "The filter"): prediction by Eq. (6)
/// from commands or wheel odometry; Mahalanobis nearest-neighbour association
/// gated by a chi-square quantile with a duplicate guard; correction by
/// Algorithm 1 (classical) or Algorithm 2 (feature updating selection); new
/// features by the inverse observation models; the secondary map of seen
/// segments. No clocks, printing or files: the caller times it.
class EkfSlam {
 public:
  /// X_WR0: known initial pose of R (the point of control h) in W; its
  /// covariance is from `params` (zero by default, as in the paper). X_RS:
  /// the laser mount on R. With the process model of kind
  /// odometry, only the increments of
  /// X_OR between consecutive records enter, so any fixed frame O works; the
  /// first record is their reference (it predicts no motion).
  /// `rng`: the stream of the `random` selection policy (only the selective
  /// filter with that policy draws from it); pass one forked from the run's
  /// seed by name so that the filter stays deterministic by seed.
  /// Throws ParamError if `params` is invalid and SlamInputError if a pose is
  /// not finite.
  EkfSlam(const EkfParams& params, CorrectionMode mode, const Pose2& X_WR0, const Pose2& X_RS,
          Rng rng = Rng(0));

  /// Predicts from the record's input over record.dt_s (the command, or the
  /// odometry increment since the previous record), then, if `features` is
  /// not null, associates its lines and corners (given in S) with the map,
  /// corrects, adds new features and extends the seen segments.
  /// `features == nullptr`: prediction only. Throws SlamInputError on bad
  /// data (checked before anything changes: the filter is left as it was).
  StepReport Step(const SensorRecord& record, const ScanFeatures* features);

  /// Estimated pose of R in W.
  Pose2 X_WR() const;
  /// Covariance of (x, y, th) of R.
  Eigen::Matrix3d pose_covariance() const { return state_.pose_covariance(); }
  /// The map: every feature with its marginal covariance and, for lines, the
  /// seen segment. O(L).
  std::vector<MapFeature> Map() const;
  /// L, the number of map features.
  int num_features() const { return state_.num_features(); }
  /// The state xi = [x, y, th, f_1, ...] (for tests; lines as the filter
  /// holds them, see SlamState).
  const Eigen::VectorXd& state() const { return state_.mean(); }
  /// A copy of P, n x n (for tests; O(n^2)).
  Eigen::MatrixXd covariance() const { return state_.covariance(); }
  /// The underlying state (for tests and benchmarks).
  const SlamState& slam_state() const { return state_; }
  /// The mode this filter was built with.
  CorrectionMode mode() const { return mode_; }
  /// A feature of a prior map (StartFrom), in W: its type, parameters,
  /// and for lines the seen segment and side (as seen_side()).
  struct PriorFeature {
    FeatureType type = FeatureType::kLine;
    Eigen::Vector2d params = Eigen::Vector2d::Zero();
    LineSegment segment;
    int seen_side = 0;
  };
  /// SlamState::StartFrom: before any feature, the filter starts from a
  /// prior over its self-calibration (if any) and `features`, joint
  /// covariance `covariance` over [c, features]. Returns the features' ids.
  std::vector<int> StartFrom(const Eigen::VectorXd& calibration,
                             const std::vector<PriorFeature>& features,
                             const Eigen::MatrixXd& covariance);
  /// Feature k's id, and the index of the feature with id `id` (-1: none,
  /// e.g. removed as a duplicate line).
  int id(int k) const { return info_[k].id; }
  int IndexOfId(int id) const;
  /// Line feature k: the side of the line (in its state form) the sensor
  /// saw it from, the sign of r - p_WS . (cos al, sin al) (+1 or -1); 0 for
  /// corners.
  int seen_side(int k) const { return info_[k].seen_side; }
  /// Feature k's seen segment along its line (lines only).
  const LineSegment& segment(int k) const { return info_[k].segment; }

 private:
  // One observation of a scan, as the filter uses it.
  struct Observation {
    FeatureType type;
    Eigen::Vector2d z;
    Eigen::Matrix2d R;
    // d z / d (laser range bias), in z's form.
    Eigen::Vector2d range_bias_gradient;
    // Seen endpoints in S (lines only).
    Eigen::Vector2d p_SA;
    Eigen::Vector2d p_SB;
  };
  // Per map feature, besides the state: id and the secondary map.
  struct FeatureInfo {
    int id;
    LineSegment segment;
    // Lines: the side of the line (in its state form (r, al)) the sensor saw
    // it from, the sign of r - p_WS . (cos al, sin al); 0 for corners.
    int seen_side = 0;
  };

  // The signed distance r - p_WS . (cos al, sin al) of the sensor from line
  // feature k, in the line's state form, at the current estimate.
  double SensorSideOfLine(int k) const;

  // Observations of `features` with their checked, inflated covariances.
  std::vector<Observation> CollectObservations(const ScanFeatures& features) const;
  // The squared Mahalanobis distances, observations x features.
  Eigen::MatrixXd MahalanobisDistances(const std::vector<Observation>& observations) const;
  // Whether line observation `observation`, seen from X_WS, passes the
  // segment gate (EkfParams::line_match_max_gap_m) of map line k.
  bool SegmentsMeet(int k, const Observation& observation, const Pose2& X_WS) const;
  // Extends line k's seen segment with an observation's endpoints, seen from
  // the current pose estimate.
  void GrowSegment(int k, const Observation& observation);
  // Whether map lines a and b are one wall seen twice
  // (EkfParams::duplicate_line_distance_m), at the current estimate.
  bool SameWall(int a, int b) const;
  // For each line in `touched` (feature indices, those whose segments grew
  // or that are new this step), removes the less certain line of every pair
  // SameWall with it; the kept line's segment covers both. Returns how many
  // lines were removed.
  int RemoveDuplicateLines(std::vector<int> touched);

  // The steps of Step(), in order.
  // The motion input of `record` (odometry increment or command, with the
  // slip and skid terms); throws SlamInputError on a bad record. Changes
  // nothing.
  MotionInput CheckedMotionInput(const SensorRecord& record) const;
  // Predicts with `input` and keeps the record's odometry pose and command
  // as the reference of the next step.
  void Predict(const SensorRecord& record, const MotionInput& input);
  // new_features_need_match: when the map holds features and no observation
  // matched, turns every kNew of `association` into kUnanchored.
  void HoldBackUnanchored(Association* association) const;
  // The matched observations that correct, with their indices into
  // `observations` in `matched_observation`: all matches except corners
  // whose two lines matched too (unless correct_corners_of_matched_lines).
  // Counts matched, redundant, new and ambiguous ones in `report`
  // (num_observed must be set).
  std::vector<MatchedObservation> SelectMatches(const Association& association,
                                                const std::vector<Observation>& observations,
                                                const ScanFeatures& features, StepReport* report,
                                                std::vector<int>* matched_observation) const;
  // Adds the new observations to the map from the current pose, lines
  // first; a new corner of two map lines is their intersection when
  // corners_from_map_lines. Counts those corners in `report`.
  void AddNewFeatures(const Association& association,
                      const std::vector<Observation>& observations, const ScanFeatures& features,
                      StepReport* report);

  EkfParams params_;
  CorrectionMode mode_;
  MotionIntegration integration_;  // of params_.process_model
  SelectionPolicy policy_;         // params_.selection_policy
  Rng rng_;                        // draws of SelectionPolicy::kRandom
  SlamState state_;
  double gate_;
  double new_feature_threshold_;
  Pose2 X_OR_previous_;
  bool has_odometry_ = false;  // whether X_OR_previous_ holds a record's pose
  Twist2 previous_command_;    // the command of the record before (zero at first)
  std::vector<FeatureInfo> info_;
  int next_id_ = 0;
};

}  // namespace mjslam::slam
