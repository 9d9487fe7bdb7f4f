#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/pose2.h"
#include "slam/motion_model.h"
#include "slam/observation_models.h"
#include "slam/slam_params.h"

namespace mjslam::slam {

/// The EKF-SLAM state xi = [x, y, th, f_1, ..., f_L] of frame R and the map,
/// its covariance P, and the sparse operations of the paper's filter on them
/// (slam/README.md, "The filter"): prediction (Eqs. 1-2) touching only the
/// pose rows and columns, augmentation with a new feature, and one sequential
/// correction (Algorithm 1's body) that uses 5 columns of P and a symmetric
/// rank-2 downdate. Feature k occupies state indices 3 + 2k and 4 + 2k.
///
/// P is stored in a buffer with spare capacity (doubled when full, columns
/// padded to 64-byte multiples), so adding a feature costs O(n), not a copy.
/// P is kept exactly symmetric: every update writes both triangles with the
/// same floating-point values.
///
/// Line features keep the (r, al) the filter moved them to: r may become
/// negative only for a line passing through W's origin within its
/// uncertainty; PredictLine canonicalises the prediction, so this is
/// harmless, and EkfSlam::Map() reports the canonical form.
class SlamState {
 public:
  /// Self-calibration (SelfCalibrationParams): when on, the state is
  /// [x, y, th, q_d, q_th, k, b, s, features], the five entries at these
  /// state indices; the odometry's three change the prediction, the laser's
  /// two every observation (z = h(pose, f) + E (b, s), E = [g, (z_0, 0)],
  /// g the observation's range_bias_gradient).
  static constexpr int kCalibrationSize = 5;
  static constexpr int kDistanceScale = 3;
  static constexpr int kHeadingScale = 4;
  static constexpr int kHeadingPerMetre = 5;
  static constexpr int kRangeBias = 6;
  static constexpr int kRangeScale = 7;

  /// Predicted measurement of one feature from the current state, with the
  /// model's Jacobians and H P H^T (without R).
  struct Measurement {
    /// False when the model is undefined (a corner at the sensor position).
    bool valid = false;
    /// The predicted observation in S: (rho, alpha) or (range, bearing).
    Eigen::Vector2d h = Eigen::Vector2d::Zero();
    /// d h / d(x, y, th) of R.
    Eigen::Matrix<double, 2, 3> H_pose = Eigen::Matrix<double, 2, 3>::Zero();
    /// d h / d feature.
    Eigen::Matrix2d H_feature = Eigen::Matrix2d::Zero();
    /// H P H^T over the 5x5 block of the pose and the feature, plus, once
    /// ToObservation has added the laser's systematic errors, their terms.
    Eigen::Matrix2d HPHt = Eigen::Matrix2d::Zero();
    /// With self-calibration: [H_pose H_feature] P_(pose, f),(b, s), the
    /// model prediction's covariance with the laser's bias and scale (0
    /// without).
    Eigen::Matrix2d HP_laser = Eigen::Matrix2d::Zero();
  };

  /// A state with no features: pose (x, y, th) of R in W (metres, radians),
  /// its 3x3 covariance (symmetric PSD, may be zero), and the laser mount
  /// X_RS used by the observation models. `jacobians`: where the prediction's
  /// A and every observation's H are evaluated. kCurrent: at the current
  /// mean. kFirstEstimates (FEJ): each feature at its first estimate (its
  /// value when added), the pose at its predicted estimate of the current
  /// step (the initial pose before the first prediction), and A of the
  /// prediction from the previous predicted pose to the new one; the
  /// predictions h themselves and W stay at the current mean.
  /// `calibration_std`: empty (no self-calibration) or the five prior
  /// standard deviations of (q_d, q_th, k, b, s), each >= 0; the entries
  /// start at 0, uncorrelated with the pose.
  SlamState(const Eigen::Vector3d& pose_WR, const Eigen::Matrix3d& pose_covariance,
            const Pose2& X_RS, JacobianPoint jacobians = JacobianPoint::kCurrent,
            const Eigen::VectorXd& calibration_std = Eigen::VectorXd());

  /// n = v + 2 L, v = 3 (+ 5 with self-calibration, + 5 with its copy c0).
  int dimension() const { return n_; }
  /// Whether the state holds the five self-calibration entries.
  bool calibrated() const { return vehicle_size_ > 3; }
  /// The self-calibration entries (q_d, q_th, k, b, s); empty without.
  Eigen::VectorXd calibration() const { return x_.segment(3, vehicle_size_ - 3); }
  /// L.
  int num_features() const { return static_cast<int>(types_.size()); }
  /// Type of feature k.
  FeatureType feature_type(int k) const { return types_[k]; }
  /// State index of feature k's first component.
  int FeatureIndex(int k) const { return vehicle_size_ + shared_size_ + 2 * k; }

  /// A state with no features yet starts from a prior over the
  /// self-calibration entries c (with self-calibration; else none) and the
  /// features `types` with means `features` (2 each, in order), with joint
  /// covariance `covariance` over [c, features] (symmetric PSD, zero on
  /// entries not estimated); the pose keeps its mean and covariance,
  /// uncorrelated with them. With self-calibration the state also gains a
  /// copy c0 of c at SharedIndex(), [pose, c, c0, features], that no
  /// prediction moves: the value c had at the start, which corrections
  /// estimate through its correlations (SubmapFilter's shared part).
  void StartFrom(const Eigen::VectorXd& calibration, const std::vector<FeatureType>& types,
                 const Eigen::VectorXd& features, const Eigen::MatrixXd& covariance);
  /// State index of c0 (StartFrom); -1 without.
  int SharedIndex() const { return shared_size_ > 0 ? vehicle_size_ : -1; }

  /// The mean xi (size n).
  const Eigen::VectorXd& mean() const { return x_; }
  /// (x, y, th) of R in W.
  Eigen::Vector3d pose() const { return x_.head<3>(); }
  /// Parameters of feature k: (r, al) or p_WC.
  Eigen::Vector2d feature(int k) const { return x_.segment<2>(FeatureIndex(k)); }
  /// The n x n covariance P, a view into the buffer.
  Eigen::Block<const Eigen::MatrixXd> covariance() const {
    return P_.topLeftCorner(n_, n_);
  }
  /// P's 3x3 pose block.
  Eigen::Matrix3d pose_covariance() const { return P_.topLeftCorner<3, 3>(); }
  /// P's 2x2 block of feature k.
  Eigen::Matrix2d feature_covariance(int k) const {
    return P_.block<2, 2>(FeatureIndex(k), FeatureIndex(k));
  }
  /// P's 5x5 block of the pose and feature k (pose first).
  Eigen::Matrix<double, 5, 5> JointCovariance(int k) const;
  /// The laser mount.
  const Pose2& X_RS() const { return X_RS_; }
  /// The points the Jacobians are evaluated at (size n): with
  /// kFirstEstimates the pose's predicted estimate and each feature's first
  /// estimate; with kCurrent the mean.
  const Eigen::VectorXd& linearization_point() const {
    return jacobians_ == JacobianPoint::kFirstEstimates ? x_first_ : x_;
  }
  /// Columns allocated for P (>= n), for tests of the growth policy.
  int capacity() const { return static_cast<int>(P_.cols()); }

  /// Prediction, Eqs. (1)-(2) with Eq. (6): pose <- f(pose, increment),
  /// P <- A P A^T + W Q W^T + s^2 n n^T with Q = input.covariance (A at the
  /// mean, or from the previous predicted pose with kFirstEstimates), for the
  /// control point `a_m` ahead of the axle; s^2 = input.lateral_variance_m2
  /// and n the unit vector across the mid-arc heading (position rows only).
  /// O(n): only the pose rows and columns change.
  /// With self-calibration the increment (d, dth) is first corrected to
  /// ((1 + q_d) d + k B^2 / 4 dth, (1 + q_th) dth + k d), B the input's
  /// axle_track_m, its covariance carried through, and
  /// A extended by d pose' / d (q_d, q_th, k).
  void Predict(const MotionInput& input, double a_m);

  /// Predicted measurement of feature k at the current mean, canonical for
  /// lines. O(1).
  Measurement Measure(int k) const;
  /// Measure(k) for comparison with observation z: a line's prediction in
  /// z's polar form (AlignLineToObservation). O(1).
  /// `range_bias_gradient`: the observation's (LineObservation's or
  /// CornerObservation's); with self-calibration the prediction then adds
  /// the laser's errors, E (b, s), and H P H^T their covariance
  /// (ToObservation).
  Measurement MeasureFor(int k, const Eigen::Vector2d& z,
                         const Eigen::Vector2d& range_bias_gradient = Eigen::Vector2d::Zero()) const;
  /// Measure(k)'s result made a prediction of observation z: a line's in z's
  /// polar form, then, with self-calibration, the laser's systematic errors
  /// added to h and H P H^T.
  void ToObservation(FeatureType type, const Eigen::Vector2d& z,
                     const Eigen::Vector2d& range_bias_gradient, Measurement* m) const;

  /// Augments the state with a feature initialised from observation z with
  /// covariance R (2x2 SPD) by the inverse observation model g:
  ///   f = g(pose, z),  P_ff = G_pose P_pp G_pose^T + G_z R G_z^T,
  ///   P_fx = G_pose P_px  (the pose rows of P, all columns).
  /// With kFirstEstimates, G_pose is taken at the pose's linearisation point
  /// and f (that of the observation h(pose_lin, f)).
  /// O(n) (amortised: the buffer doubles when full). Returns the new index k.
  /// With self-calibration z is first corrected for the laser's errors,
  /// z - E (b, s), and G extended by -G_z E on their columns.
  int AddFeature(FeatureType type, const Eigen::Vector2d& z, const Eigen::Matrix2d& R,
                 const Eigen::Vector2d& range_bias_gradient = Eigen::Vector2d::Zero());

  /// Augments the state with the corner where map lines a and b meet, a
  /// function of the state: f = IntersectLines(f_a, f_b) = c, P_fx = J P_(ab)x,
  /// P_ff = J P_(ab)(ab) J^T with J = d c / d(f_a, f_b). It adds no
  /// information: the corner is exactly as uncertain as its lines, and
  /// correlated with them. O(n) (amortised). Returns the new index k.
  /// Precondition (checked): a != b are lines that are not parallel.
  int AddLineIntersection(int a, int b);

  /// Removes feature k from the state: its mean and its rows and columns of
  /// P. The rest is the exact Gaussian marginal of the other entries, so no
  /// information about them is lost or invented; features after k move down
  /// one index. O(n^2) (the rows and columns after k move).
  void RemoveFeature(int k);
  /// One sequential EKF correction (Algorithm 1, sentences iv-vi) with
  /// observation z of feature k, covariance R (SPD):
  ///   nu = z - h(xi) (angle wrapped; a line's h in z's polar form),
  ///   S = H P H^T + R, K = P H^T S^-1,
  ///   xi <- xi + K nu,  P <- P - K S K^T = P - V V^T with V = P H^T L^-T,
  ///   S = L L^T. P H^T uses 5 columns of P; the downdate is O(n^2) with no
  ///   dense n x n product. Angles are wrapped afterwards. Precondition
  ///   (checked): Measure(k).valid and S positive definite.
  void Update(int k, const Eigen::Vector2d& z, const Eigen::Matrix2d& R,
              const Eigen::Vector2d& range_bias_gradient = Eigen::Vector2d::Zero());

  /// The innovation covariance S = H P H^T + R of observation z of feature k
  /// with covariance R. O(1).
  Eigen::Matrix2d InnovationCovariance(
      int k, const Eigen::Vector2d& z, const Eigen::Matrix2d& R,
      const Eigen::Vector2d& range_bias_gradient = Eigen::Vector2d::Zero()) const;

 private:
  // Makes room for `n` state entries, doubling the buffer if needed.
  void Reserve(int n);
  // Ends an augmentation whose P rows and columns are written: appends the
  // mean f of a feature of `type` and returns its index.
  int Append(FeatureType type, const Eigen::Vector2d& f);
  // The steps of Update, in order. WhitenedGain computes V = P H^T L^-T
  // into scratch_ (H = [H_pose at the pose, H_feature at state index j]),
  // with S = H P H^T + R = L L^T, and returns L^-1 nu, so that K nu = V L^-1 nu.
  // Precondition (checked): S positive definite.
  // E: d h / d (b, s) with self-calibration (unused without).
  Eigen::Vector2d WhitenedGain(int j, const Eigen::Matrix<double, 2, 3>& H_pose,
                               const Eigen::Matrix2d& H_feature, const Eigen::Matrix2d& E,
                               const Eigen::Matrix2d& R, const Eigen::Vector2d& nu);
  // Moves the pose by Eq. (6) with `input` (PredictPose) and returns A =
  // d pose' / d pose (FEJ's with kFirstEstimates, which also records the new
  // predicted pose); *W receives d pose' / d increment.
  Eigen::Matrix3d MovePose(const MotionInput& input, double a_m, Eigen::Matrix<double, 3, 2>* W);
  // Adds the input's sideways slip to the new pose block *P_pp.
  void AddLateralSlip(const MotionInput& input, Eigen::Matrix3d* P_pp) const;
  // The prediction with self-calibration (Predict).
  void PredictCalibrated(const MotionInput& input, double a_m);
  // E = [g, (z_0, 0)]: d z / d (b, s).
  static Eigen::Matrix2d LaserErrorJacobian(const Eigen::Vector2d& z,
                                            const Eigen::Vector2d& range_bias_gradient);
  // xi <- xi + V w and P <- P - V V^T with V in scratch_ (from WhitenedGain).
  void ApplyGain(const Eigen::Vector2d& w);
  // Wraps the heading and every line's alpha into (-pi, pi].
  void WrapAngles();
  // The prediction h of feature k at the mean and its Jacobians at the
  // linearisation point (linearization_point()), a line's Jacobians in the
  // polar form of h. False when the model is undefined at either point (a
  // corner at the sensor).
  bool PredictWithJacobians(int k, Eigen::Vector2d* h, Eigen::Matrix<double, 2, 3>* H_pose,
                            Eigen::Matrix2d* H_feature) const;

  // The random walk of the odometry's errors (MotionInput::wheel_slip_drift_per_m).
  void AddCalibrationDrift(const MotionInput& raw);

  Pose2 X_RS_;
  // 3, or 3 + kCalibrationSize with self-calibration.
  int vehicle_size_ = 3;
  // 0, or kCalibrationSize with the copy c0 (StartFrom).
  int shared_size_ = 0;
  int n_ = 3;
  Eigen::VectorXd x_;
  // Capacity x capacity buffer; P is its top-left n_ x n_ block.
  Eigen::MatrixXd P_;
  JacobianPoint jacobians_;
  // The prior standard deviations of the self-calibration entries (empty
  // without it): an entry with 0 is not estimated.
  Eigen::VectorXd calibration_std_;
  // With kFirstEstimates: the pose's predicted estimate and the features'
  // first estimates (size n); empty otherwise.
  Eigen::VectorXd x_first_;
  std::vector<FeatureType> types_;
  // Scratch for P H^T and V, capacity x 2.
  Eigen::MatrixXd scratch_;
};

}  // namespace mjslam::slam
