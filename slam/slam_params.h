#pragma once

#include <iterator>
#include <string>
#include <variant>
#include <vector>

#include "common/params.h"
#include "slam/feature_extraction.h"
#include "slam/filter_params.h"
#include "slam/innovation_check.h"

namespace mjslam::slam {

/// How the prediction integrates the paper's Eq. (6) over one step
/// (`slam.ekf.process_model.integration`; docs/method.md, departure 9).
enum class MotionIntegration {
  /// The axle centre on the arc the held input describes (the default).
  kExact,
  /// The paper's forward-Euler step, with the heading at the start of the
  /// period.
  kEuler,
};

/// Which MAX matched observations the selective filter corrects with
/// (`slam.ekf.selection_policy`; docs/method.md, "Selection policies").
enum class SelectionPolicy {
  /// The paper's: repeatedly the smallest sum(eig(B)) under the current P.
  kCriterion,
  /// The first MAX in extraction order (lines, then corners).
  kFirst,
  /// MAX drawn uniformly without replacement from a seeded stream.
  kRandom,
  /// Repeatedly the largest sum(eig(B)): the least informative.
  kLeastInformative,
  /// Repeatedly the one leaving the smallest det of the pose covariance.
  kDeterminant,
};

/// Where the filter evaluates the Jacobians of the prediction and of the
/// observations (`slam.ekf.jacobians`; docs/method.md, "First-estimates Jacobians").
enum class JacobianPoint {
  /// At the current estimate, as the standard EKF (the paper's).
  kCurrent,
  /// First-estimates Jacobians (FEJ-EKF; Huang, Mourikis and Roumeliotis,
  /// IJRR 29(5), 2010): every feature at its first estimate, the pose of a
  /// step at its predicted (prior) estimate, in the prediction and in every
  /// correction of that step, so that the linearised model keeps the
  /// unobservable global translation and rotation unobservable.
  kFirstEstimates,
};

/// The names the YAML uses, in enum order.
inline constexpr const char* kMotionIntegrationNames[] = {"exact", "euler"};
/// The names the YAML uses, in enum order.
inline constexpr const char* kJacobianPointNames[] = {"current", "first_estimates"};
/// The names the YAML uses, in enum order.
inline constexpr const char* kSelectionPolicyNames[] = {"criterion", "first", "random",
                                                        "least_informative", "determinant"};

/// The enum of a `slam.ekf.process_model.integration` value. Throws ParamError for
/// a name not in kMotionIntegrationNames.
MotionIntegration MotionIntegrationFromName(const std::string& name);
/// The enum of a `slam.ekf.jacobians` value. Throws ParamError for a name not
/// in kJacobianPointNames.
JacobianPoint JacobianPointFromName(const std::string& name);
/// The enum of a `slam.ekf.selection_policy` value. Throws ParamError for a
/// name not in kSelectionPolicyNames.
SelectionPolicy SelectionPolicyFromName(const std::string& name);

/// Noise of the commanded velocities as the filter's input (the process
/// model of kind `command`). The robot's real motion differs from the command
/// through the wheel dynamics (lag, acceleration limits, slip), so these must
/// cover that difference, not only actuator noise. One standard deviation
/// each, held over the record's `dt_s`: sigma_v = v_std_mps + v_fraction |v|
/// + change_fraction |v - v_prev|, likewise sigma_w. Serialized under
/// `slam.ekf.process_model.noise.*` (with `kind: command`).
struct CommandNoiseParams {
  /// The process model's `kind` that has this noise.
  static constexpr const char* kKind = "command";
  /// Constant part of the linear-velocity noise, m/s.
  double v_std_mps = 0.03;
  /// Part of the linear-velocity noise proportional to |v| (dimensionless).
  double v_fraction = 0.1;
  /// Constant part of the angular-velocity noise, rad/s.
  double w_std_radps = 0.03;
  /// Part of the angular-velocity noise proportional to |w| (dimensionless).
  double w_fraction = 0.1;
  /// Part of the noise proportional to the change of the command since the
  /// previous record, |v - v_prev| and |w - w_prev| (dimensionless): the
  /// wheels follow a step in the command with a lag, so the motion over the
  /// period lies between the two commands.
  double change_fraction = 0.5;

  /// The keys before the process model was a tagged choice.
  static constexpr RetiredKey kRetiredKeys[] = {
      {"v_noise_std_mps", "v_std_mps", ""},
      {"v_noise_fraction", "v_fraction", ""},
      {"w_noise_std_radps", "w_std_radps", ""},
      {"w_noise_fraction", "w_fraction", ""},
      {"change_noise_fraction", "change_fraction", ""}};

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(v_std_mps));
    a->Visit(MJSLAM_NVP(v_fraction));
    a->Visit(MJSLAM_NVP(w_std_radps));
    a->Visit(MJSLAM_NVP(w_fraction));
    a->Visit(MJSLAM_NVP(change_fraction));
  }
  /// Every out-of-range field, keys relative to this struct.
  std::vector<ParamProblem> Validate() const;
  /// Throws ParamError listing every problem of Validate().
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }
};

/// Noise of the wheel-odometry increment as the filter's input (the process
/// model of kind `odometry`), per record, with d the distance increment (m)
/// and dth the heading increment (rad) between two records. Wheel slip is a
/// random walk: its variance grows with the distance rolled and the angle
/// turned, not with their squares (so the model does not depend on the
/// record rate):
///   sigma_d^2   = distance_std_m^2 + distance_std_m_per_sqrt_m^2 |d|
///                 + distance_std_m_per_sqrt_rad^2 |dth|,
///   sigma_dth^2 = heading_std_rad^2 + heading_std_rad_per_sqrt_m^2 |d|
///                 + heading_std_rad_per_sqrt_rad^2 |dth|.
/// The defaults are twice the simulator's default slip (0.5 % of a metre per
/// wheel, 0.33 m track: 0.0035 m and 0.021 rad after 1 m, 0.0087 rad after
/// 1 rad turned). Serialized under `slam.ekf.process_model.noise.*` (with
/// `kind: odometry`).
struct OdometryNoiseParams {
  /// The process model's `kind` that has this noise.
  static constexpr const char* kKind = "odometry";
  /// Noise floor of the distance increment per record, metres.
  double distance_std_m = 0.0005;
  /// Standard deviation of the distance after 1 m rolled, m per sqrt(m).
  double distance_std_m_per_sqrt_m = 0.007;
  /// Standard deviation of the distance after 1 rad turned, m per sqrt(rad):
  /// the wheels' slip moves a robot that turns on the spot forward or back.
  double distance_std_m_per_sqrt_rad = 0.0;
  /// Noise floor of the heading increment per record, radians.
  double heading_std_rad = 0.0005;
  /// Standard deviation of the heading after 1 m rolled, rad per sqrt(m).
  double heading_std_rad_per_sqrt_m = 0.04;
  /// Standard deviation of the heading after 1 rad turned, rad per sqrt(rad).
  double heading_std_rad_per_sqrt_rad = 0.02;

  /// The keys before the process model was a tagged choice.
  static constexpr RetiredKey kRetiredKeys[] = {
      {"distance_noise_std_m", "distance_std_m", ""},
      {"distance_noise_std_m_per_sqrt_m", "distance_std_m_per_sqrt_m", ""},
      {"distance_noise_std_m_per_sqrt_rad", "distance_std_m_per_sqrt_rad", ""},
      {"heading_noise_std_rad", "heading_std_rad", ""},
      {"heading_noise_std_rad_per_sqrt_m", "heading_std_rad_per_sqrt_m", ""},
      {"heading_noise_std_rad_per_sqrt_rad", "heading_std_rad_per_sqrt_rad", ""}};

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(distance_std_m));
    a->Visit(MJSLAM_NVP(distance_std_m_per_sqrt_m));
    a->Visit(MJSLAM_NVP(distance_std_m_per_sqrt_rad));
    a->Visit(MJSLAM_NVP(heading_std_rad));
    a->Visit(MJSLAM_NVP(heading_std_rad_per_sqrt_m));
    a->Visit(MJSLAM_NVP(heading_std_rad_per_sqrt_rad));
  }
  /// Every out-of-range field, keys relative to this struct.
  std::vector<ParamProblem> Validate() const;
  /// Throws ParamError listing every problem of Validate().
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }
};

/// Sideways motion of R that Eq. (6) lacks, with either input
/// (`slam.ekf.process_model.lateral.*`).
struct LateralMotionParams {
  /// Lateral slip of R per radian turned, one standard deviation, metres per
  /// radian: what the skid below leaves unmodelled. The prediction adds
  /// (k |dth|)^2 of variance across the mid-arc heading (docs/method.md,
  /// departure 10).
  double slip_std_m_per_rad = 0.005;
  /// Lateral slip of R per metre rolled, one standard deviation after 1 m,
  /// metres per sqrt(metre): a sideways random walk over the distance
  /// driven. The prediction adds k^2 |d| of variance across the mid-arc
  /// heading, in addition to the term per radian above.
  double slip_std_m_per_sqrt_m = 0.0;
  /// Sideways skid of the axle centre in turns, seconds: Eq. (6) has no
  /// sideways motion, but tyres skid to the outside of a turn at a speed
  /// proportional to the centripetal acceleration, c v w. The prediction
  /// moves R by c d dth / dt across the mid-arc heading, to the outside
  /// (d, dth: the step's increment; nothing when dt = 0). 0: Eq. (6) as in
  /// the paper. The default is the simulated Pioneer's, measured from the
  /// true motion (docs/method.md, departure 13).
  double skid_s = 0.0102;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(slip_std_m_per_rad));
    a->Visit(MJSLAM_NVP(slip_std_m_per_sqrt_m));
    a->Visit(MJSLAM_NVP(skid_s));
  }
  /// Every out-of-range field, keys relative to this struct.
  std::vector<ParamProblem> Validate() const;
  /// Throws ParamError listing every problem of Validate().
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }
};

/// The process model (Eq. 6) driven by one kind of input, whose noise is
/// `Noise` (CommandNoiseParams or OdometryNoiseParams; GTSAM's noise model
/// as a class). The two kinds share the integration and the lateral motion;
/// each has only its own noise. Serialized under `slam.ekf.process_model.*`
/// as a tagged choice: `kind: command` or `kind: odometry`, then this
/// kind's keys (config/README.md, "Tagged choices").
template <typename Noise>
struct ProcessModel {
  /// The `kind` of this process model.
  static constexpr const char* kKind = Noise::kKind;
  /// How Eq. (6) is integrated over a step: "exact" (the axle centre on an
  /// arc, docs/method.md departure 9) or "euler" (the paper's forward-Euler
  /// step). Read as MotionIntegration.
  std::string integration = "exact";
  /// The input's noise.
  Noise noise;
  /// Sideways motion Eq. (6) lacks.
  LateralMotionParams lateral;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(integration));
    a->Visit(MJSLAM_NVP(noise));
    a->Visit(MJSLAM_NVP(lateral));
  }
  /// Every out-of-range field, keys relative to this struct.
  std::vector<ParamProblem> Validate() const {
    ParamChecker check;
    check.OneOf("integration", integration,
                std::vector<std::string>(std::begin(kMotionIntegrationNames),
                                         std::end(kMotionIntegrationNames)));
    check.Merge("noise", noise.Validate());
    check.Merge("lateral", lateral.Validate());
    return check.problems();
  }
};

/// The paper's: the record's command held over its dt (`kind: command`).
using CommandProcessModel = ProcessModel<CommandNoiseParams>;
/// The wheel-odometry increment between consecutive records, turned into the
/// equivalent input (`kind: odometry`; docs/method.md, departure 2).
using OdometryProcessModel = ProcessModel<OdometryNoiseParams>;
/// What drives the prediction: one of the two kinds
/// (`slam.ekf.process_model`). Dispatch with std::visit or std::get_if.
using ProcessModelParams = std::variant<CommandProcessModel, OdometryProcessModel>;

/// Whether `model` is of kind odometry (else: command).
inline bool PredictsFromOdometry(const ProcessModelParams& model) {
  return std::holds_alternative<OdometryProcessModel>(model);
}
/// The integration of either kind.
inline const std::string& IntegrationOf(const ProcessModelParams& model) {
  return std::visit([](const auto& m) -> const std::string& { return m.integration; }, model);
}
/// The lateral motion of either kind.
inline const LateralMotionParams& LateralOf(const ProcessModelParams& model) {
  return std::visit([](const auto& m) -> const LateralMotionParams& { return m.lateral; },
                    model);
}
/// Every out-of-range field of either kind, keys relative to it.
inline std::vector<ParamProblem> ValidateProcessModel(const ProcessModelParams& model) {
  return std::visit([](const auto& m) { return m.Validate(); }, model);
}

/// Self-calibration (docs/method.md, "Self-calibration"): the robot's
/// systematic errors estimated in the state, next to the pose, each from a
/// zero-mean prior of the standard deviation given here (the envelope of the
/// robots the filter is meant for). With any of them > 0 the state gains
/// five entries after the pose, in this order:
///   q_d  the motion increment's distance scale error;
///   q_th the heading increment's scale error;
///   k    the heading change per metre (rad/m): unequal wheels drive an arc,
///        and move forward or back when turning on the spot: with the track
///        B (EkfParams::axle_track_m), d -> (1 + q_d) d + k B^2 / 4 dth,
///        dth -> (1 + q_th) dth + k d
///        (to first order the effect of each wheel's own radius error);
///   b    the laser's range bias (m): every range r -> r + b;
///   s    the laser's range scale error: r -> (1 + s) r.
/// An entry whose standard deviation is 0 stays at 0 (its rows of P are 0).
/// Serialized under `slam.ekf.self_calibration.*`; all 0 (the default and
/// the paper): the state is the paper's [x, y, th, features].
struct SelfCalibrationParams {
  double distance_scale_std = 0.0;
  double heading_scale_std = 0.0;
  double heading_per_m_std_rad = 0.0;
  double range_bias_std_m = 0.0;
  double range_scale_std = 0.0;
  /// Drift of each wheel's slip fraction, one standard deviation per
  /// sqrt(metre) that wheel rolls: the odometry's errors (q_d, q_th, k)
  /// are a random walk, not constants, so that slip correlated over metres
  /// (wet patches, tyre wear, a wheel's load) is tracked. A wheel's travel
  /// delta adds s^2 delta of variance to its slip; q_d and q_th move with the
  /// mean of the wheels' slips, k with their difference over the track B:
  /// Q_cal = s^2 (delta_l + delta_r) [[1/4, 1/4, 0], [1/4, 1/4, 0], [0, 0, 1/B^2]]
  /// on the entries that are estimated. 0: constant errors.
  double wheel_slip_drift_std_per_sqrt_m = 0.0;
  /// True when any entry is estimated.
  bool Enabled() const {
    return distance_scale_std > 0.0 || heading_scale_std > 0.0 || heading_per_m_std_rad > 0.0 ||
           range_bias_std_m > 0.0 || range_scale_std > 0.0;
  }

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(distance_scale_std));
    a->Visit(MJSLAM_NVP(heading_scale_std));
    a->Visit(MJSLAM_NVP(heading_per_m_std_rad));
    a->Visit(MJSLAM_NVP(range_bias_std_m));
    a->Visit(MJSLAM_NVP(range_scale_std));
    a->Visit(MJSLAM_NVP(wheel_slip_drift_std_per_sqrt_m));
  }
  /// Every out-of-range field, keys relative to this struct.
  std::vector<ParamProblem> Validate() const;
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }
};

/// Parameters of the EKF-SLAM filters (slam/README.md, "The filter").
/// Serialized under `slam.ekf.*`.
struct EkfParams {
  /// What drives the prediction (Eq. 6) and its noise: the paper's
  /// commands (CommandProcessModel, the default) or the wheel odometry
  /// (OdometryProcessModel).
  ProcessModelParams process_model;
  /// Offset `a` of the point of control h (frame R) ahead of the wheel axle,
  /// metres (> 0). Must match the robot's (`robot.control_point_offset_m`).
  double control_point_offset_m = 0.2;
  /// The distance between the drive wheels' contact points, metres (> 0):
  /// self-calibration's cross term, which splits an increment into the two
  /// wheels' travel, uses it.
  /// Must match the robot's (`robot.axle_track_m`).
  double axle_track_m = 0.33;
  /// The systematic errors estimated in the state (SelfCalibrationParams).
  SelfCalibrationParams self_calibration;
  /// Where the Jacobians are evaluated: "current" (the standard EKF, the
  /// paper's) or "first_estimates" (FEJ-EKF, docs/method.md, "First-estimates Jacobians").
  /// Read as JacobianPoint.
  std::string jacobians = "current";

  /// Standard deviation of the initial position of R, metres (0: known start,
  /// as in the paper).
  double initial_position_std_m = 0.0;
  /// Standard deviation of the initial heading of R, radians (0: known).
  double initial_heading_std_rad = 0.0;

  /// Model-error noise added (in quadrature, one standard deviation) to the
  /// covariance the extractor gives each observation: line rho, metres.
  double extra_line_rho_std_m = 0.0;
  /// Same for line alpha, radians.
  double extra_line_alpha_std_rad = 0.0;
  /// Same for corner range, metres.
  double extra_corner_range_std_m = 0.0;
  /// Same for corner bearing, radians.
  double extra_corner_bearing_std_rad = 0.0;

  /// Data association gate: an observation matches a map feature of its type
  /// when the Mahalanobis distance d^2 = nu^T S^-1 nu is below the chi-square
  /// quantile (2 dof) of this probability, in (0, 1). 0.99 gives 9.21.
  double gate_probability = 0.99;
  /// Duplicate guard: an unmatched observation becomes a new feature only if
  /// d^2 to every map feature of its type is at least the chi-square quantile
  /// (2 dof) of this probability (>= gate_probability, < 1). Observations in
  /// between are neither matched nor added. 0.9999 gives 18.4.
  double new_feature_probability = 0.9999;
  /// Whether a line observation may match only a line feature seen from the
  /// same side: a wall's face is visible from its front only, so with the
  /// sensor clearly (3 sigma of the predicted rho) on the other side of the
  /// line than when the feature was made, the observation is of another
  /// face (the back of a thin wall, 0.15 m away) and is not compared with
  /// it. false: any line of similar (rho, alpha) in the sensor frame may
  /// match, the back face too (docs/method.md, departure 5; it does not fix
  /// the maze map loss of docs/results.md).
  bool gate_line_side = true;
  /// Whether the observations of a scan of which none matched a map feature
  /// may become new features (when the map holds any). A prediction error of
  /// a few sigma moves every observation of a scan out of the gate at once;
  /// added from that pose, they make a second copy of the walls around the
  /// robot, shifted by the error, which the next scans match and the error
  /// stays (the maze map loss, docs/results.md). true (default): such a
  /// scan adds nothing (AssociationOutcome::kUnanchored); the next
  /// prediction widens the pose's covariance and a later scan matches, or
  /// adds features once one of its observations matches. false: every
  /// observation far from the map is added, as in the paper
  /// (docs/method.md, departure 5).
  bool new_features_need_match = true;
  /// Whether a corner whose two lines both matched map features in the same
  /// scan also corrects the state. A corner is the intersection of its two
  /// lines, fitted to the same points: correcting with all three counts that
  /// information twice and makes the filter overconfident. false (default):
  /// such a corner is matched (and its segment bookkeeping kept) but left
  /// out of the correction; corners with a new or unmatched line still
  /// correct (docs/method.md, departure 11).
  bool correct_corners_of_matched_lines = false;
  /// Whether a new corner whose two lines are in the map after the step
  /// (matched, or new in the same scan) is added as the intersection of
  /// those map lines, correlated with them (SlamState::AddLineIntersection).
  /// The corner is fitted to the same points as its lines, so its own
  /// observation holds nothing they do not. false: it is added from its
  /// observation as an independent feature, as in the paper, and the map
  /// counts the scan's information twice (docs/method.md, departure 12).
  bool corners_from_map_lines = true;
  /// Segment gate of line association, metres: a line observation may match
  /// a map line only when its seen segment, projected on the map line,
  /// overlaps the map line's seen segment or stops short of it by at most
  /// this. 0 (default): no segment gate, lines are infinite as in the paper.
  /// Real buildings have many collinear walls (both sides of a corridor's
  /// doors, offices in a row), which the infinite line model confuses.
  double line_match_max_gap_m = 0.0;
  /// Duplicate map lines, metres: two map lines whose seen segments overlap
  /// by at least `duplicate_line_min_overlap_m`, seen from the same side,
  /// with each line within this distance of the other at both ends of the
  /// overlap, are one wall seen twice (a wall seen in pieces farther apart
  /// than the segment gate whose pieces grew together; a wall in front of
  /// another would hide it). The less certain of the two (larger determinant
  /// of its 2x2 covariance) is removed from the state, its marginal dropped
  /// (docs/method.md, "Duplicate lines"). 0 (default): never, as in the paper.
  double duplicate_line_distance_m = 0.0;
  /// See `duplicate_line_distance_m`, metres (> 0).
  double duplicate_line_min_overlap_m = 0.25;
  /// MAX of the paper's Algorithm 2: the most features used per correction by
  /// the selective filter (>= 1). Ignored by the classical filter.
  int max_updates = 2;
  /// How the selective filter chooses its max_updates observations:
  /// "criterion" (the paper's), "first", "random", "least_informative" or
  /// "determinant" (SelectionPolicy). Ignored by the classical filter.
  std::string selection_policy = "criterion";

  /// The flat keys of the process model before it was a tagged choice; a
  /// config that gives one is told the key that replaced it.
  static constexpr RetiredKey kRetiredKeys[] = {
      {"input", "process_model.kind", "input: odometry is now process_model: {kind: odometry}"},
      {"motion_integration", "process_model.integration", ""},
      {"command_noise", "process_model.noise",
       "with process_model.kind: command; each key without '_noise', as v_std_mps"},
      {"odometry_noise", "process_model.noise",
       "with process_model.kind: odometry; each key without '_noise', as distance_std_m"},
      {"lateral_slip_std_m_per_rad", "process_model.lateral.slip_std_m_per_rad", ""},
      {"lateral_slip_std_m_per_sqrt_m", "process_model.lateral.slip_std_m_per_sqrt_m", ""},
      {"lateral_skid_s", "process_model.lateral.skid_s", ""}};

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(process_model));
    a->Visit(MJSLAM_NVP(control_point_offset_m));
    a->Visit(MJSLAM_NVP(axle_track_m));
    a->Visit(MJSLAM_NVP(self_calibration));
    a->Visit(MJSLAM_NVP(jacobians));
    a->Visit(MJSLAM_NVP(initial_position_std_m));
    a->Visit(MJSLAM_NVP(initial_heading_std_rad));
    a->Visit(MJSLAM_NVP(extra_line_rho_std_m));
    a->Visit(MJSLAM_NVP(extra_line_alpha_std_rad));
    a->Visit(MJSLAM_NVP(extra_corner_range_std_m));
    a->Visit(MJSLAM_NVP(extra_corner_bearing_std_rad));
    a->Visit(MJSLAM_NVP(gate_probability));
    a->Visit(MJSLAM_NVP(new_feature_probability));
    a->Visit(MJSLAM_NVP(gate_line_side));
    a->Visit(MJSLAM_NVP(new_features_need_match));
    a->Visit(MJSLAM_NVP(correct_corners_of_matched_lines));
    a->Visit(MJSLAM_NVP(corners_from_map_lines));
    a->Visit(MJSLAM_NVP(line_match_max_gap_m));
    a->Visit(MJSLAM_NVP(duplicate_line_distance_m));
    a->Visit(MJSLAM_NVP(duplicate_line_min_overlap_m));
    a->Visit(MJSLAM_NVP(max_updates));
    a->Visit(MJSLAM_NVP(selection_policy));
  }
  /// Every out-of-range field, keys relative to this struct (nested ones as
  /// `process_model.noise.v_std_mps`, ...).
  std::vector<ParamProblem> Validate() const;
  /// Throws ParamError listing every problem of Validate().
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }
};

/// Everything the SLAM needs: feature extraction and filter parameters.
/// Serialized under `slam.*` (`slam.features.*`, `slam.ekf.*`, `slam.timing`).
struct SlamParams {
  /// Line and corner extraction (`slam.features.*`).
  FeatureExtractionParams features;
  /// The filters (`slam.ekf.*`).
  EkfParams ekf;
  /// When each filter runs (docs/method.md, "Real-time filter timing"):
  /// "every_scan" (every filter processes every record, whatever its
  /// processing time) or "realtime" (a filter busy with a scan for its
  /// command period skips the scans that arrive meanwhile). The string lives
  /// only here, where YAML is read; app/engine/filter_bank.h turns it into an enum.
  std::string timing = "every_scan";
  /// The run's check of each filter against its own innovations
  /// (`slam.innovation_check.*`; InnovationCheck).
  InnovationCheckParams innovation_check;
  /// The filters of the run, each named, of a kind, with settings of its own
  /// (`slam.filters`; slam/filter.h). Empty (the key absent): the paper's
  /// two, classical and selective (ResolvedFilters); the resolved config
  /// then has no `filters` key either.
  std::vector<FilterParams> filters;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(features));
    a->Visit(MJSLAM_NVP(ekf));
    a->Visit(MJSLAM_NVP(timing));
    a->Visit(MJSLAM_NVP(innovation_check));
    if (!ArchiveWrites<Archive>::value || !filters.empty()) a->Visit(MJSLAM_NVP(filters));
  }
  /// Problems of both parts, keys prefixed `features.` and `ekf.`, of
  /// `timing` and of `innovation_check.`.
  std::vector<ParamProblem> Validate() const {
    ParamChecker check;
    check.Merge("features", features.Validate());
    check.Merge("ekf", ekf.Validate());
    check.OneOf("timing", timing, {"every_scan", "realtime"});
    check.Merge("innovation_check", innovation_check.Validate());
    for (const ParamProblem& p : ValidateFilters(filters)) {
      check.Require(false, p.key, p.value, p.expected);
    }
    return check.problems();
  }
  /// Throws ParamError listing every problem of Validate().
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }
};

}  // namespace mjslam::slam
