#include "slam/slam_state.h"

#include <algorithm>
#include <cmath>

#include "common/angles.h"
#include "common/check.h"
#include "slam/fast_wrap.h"
#include "slam/feature_extraction.h"

namespace mjslam::slam {
namespace {

// Room for this many features before the first growth of the buffer.
constexpr int kInitialFeatureCapacity = 16;
// Columns of P are padded to a multiple of this many doubles (64 bytes), so
// that every column starts on a cache line and vector loads are aligned.
constexpr int kColumnPadding = 8;

int PaddedSize(int n) { return (n + kColumnPadding - 1) / kColumnPadding * kColumnPadding; }

// Largest distance at which a corner counts as sitting on the sensor, metres.
constexpr double kMinCornerRange = 1e-9;

}  // namespace

SlamState::SlamState(const Eigen::Vector3d& pose_WR, const Eigen::Matrix3d& pose_covariance,
                     const Pose2& X_RS, JacobianPoint jacobians,
                     const Eigen::VectorXd& calibration_std)
    : X_RS_(X_RS), x_(pose_WR), jacobians_(jacobians), calibration_std_(calibration_std) {
  MJSLAM_CHECK(calibration_std.size() == 0 || calibration_std.size() == kCalibrationSize);
  x_.z() = WrapAngleFast(x_.z());
  vehicle_size_ = 3 + static_cast<int>(calibration_std.size());
  n_ = vehicle_size_;
  x_.conservativeResize(n_);
  x_.tail(n_ - 3).setZero();
  if (jacobians_ == JacobianPoint::kFirstEstimates) x_first_ = x_;
  const int capacity = PaddedSize(vehicle_size_ + 2 * kInitialFeatureCapacity);
  P_ = Eigen::MatrixXd::Zero(capacity, capacity);
  P_.topLeftCorner<3, 3>() = 0.5 * (pose_covariance + pose_covariance.transpose());
  for (int i = 0; i < calibration_std.size(); ++i) {
    MJSLAM_CHECK(calibration_std[i] >= 0.0);
    P_(3 + i, 3 + i) = calibration_std[i] * calibration_std[i];
  }
  scratch_ = Eigen::MatrixXd::Zero(capacity, 2);
}

void SlamState::StartFrom(const Eigen::VectorXd& calibration,
                          const std::vector<FeatureType>& types, const Eigen::VectorXd& features,
                          const Eigen::MatrixXd& covariance) {
  MJSLAM_CHECK(num_features() == 0 && shared_size_ == 0);
  const int nc = calibrated() ? kCalibrationSize : 0;
  const int nf = 2 * static_cast<int>(types.size());
  MJSLAM_CHECK(calibration.size() == nc && features.size() == nf &&
               covariance.rows() == nc + nf && covariance.cols() == nc + nf);
  const int shared = nc;  // the copy c0
  Reserve(vehicle_size_ + shared + nf);
  shared_size_ = shared;
  n_ = vehicle_size_ + shared_size_ + nf;
  x_.conservativeResize(n_);
  x_.segment(3, nc) = calibration;
  x_.segment(vehicle_size_, shared) = calibration;
  x_.tail(nf) = features;
  types_ = types;
  // P over [pose, c, c0, features]: the pose's block stays, uncorrelated
  // with the rest; c0 is a copy of c.
  const Eigen::MatrixXd sym = 0.5 * (covariance + covariance.transpose());
  const std::vector<std::pair<int, int>> blocks = {
      {3, 0}, {vehicle_size_, 0}, {vehicle_size_ + shared, nc}};  // (state index, prior index)
  const std::vector<int> sizes = {nc, shared, nf};
  P_.block(0, 3, 3, n_ - 3).setZero();
  P_.block(3, 0, n_ - 3, 3).setZero();
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      P_.block(blocks[a].first, blocks[b].first, sizes[a], sizes[b]) =
          sym.block(blocks[a].second, blocks[b].second, sizes[a], sizes[b]);
    }
  }
  if (jacobians_ == JacobianPoint::kFirstEstimates) x_first_ = x_;
  WrapAngles();
}

Eigen::Matrix2d SlamState::LaserErrorJacobian(const Eigen::Vector2d& z,
                                              const Eigen::Vector2d& range_bias_gradient) {
  // A scale error s moves every point along its beam by s r: a line
  // (rho, alpha) becomes (rho (1 + s), alpha), a corner's range d (1 + s).
  Eigen::Matrix2d E;
  E << range_bias_gradient.x(), z.x(), range_bias_gradient.y(), 0.0;
  return E;
}

Eigen::Matrix<double, 5, 5> SlamState::JointCovariance(int k) const {
  const int j = FeatureIndex(k);
  Eigen::Matrix<double, 5, 5> block;
  block.topLeftCorner<3, 3>() = P_.topLeftCorner<3, 3>();
  block.topRightCorner<3, 2>() = P_.block<3, 2>(0, j);
  block.bottomLeftCorner<2, 3>() = P_.block<2, 3>(j, 0);
  block.bottomRightCorner<2, 2>() = P_.block<2, 2>(j, j);
  return block;
}

Eigen::Matrix3d SlamState::MovePose(const MotionInput& input, double a_m,
                                    Eigen::Matrix<double, 3, 2>* W) {
  Eigen::Matrix3d A;
  x_.head<3>() = PredictPose(x_.head<3>(), input.increment, a_m, &A, W, input.skid_per_m_rad,
                             input.integration);
  if (jacobians_ == JacobianPoint::kFirstEstimates) {
    // FEJ (Huang et al. 2010): A = d pose' / d pose is the identity but for
    // the heading column, the displacement rotated by 90 deg; take the
    // displacement from the previous predicted pose to the new one, so that
    // the propagations chain through the same poses as the observations.
    A(0, 2) = -(x_.y() - x_first_.y());
    A(1, 2) = x_.x() - x_first_.x();
    x_first_.head<3>() = x_.head<3>();
  }
  return A;
}

void SlamState::AddLateralSlip(const MotionInput& input, Eigen::Matrix3d* P_pp) const {
  // Sideways slip: variance across the mid-arc heading, position only.
  if (input.lateral_variance_m2 <= 0.0) return;
  const double mid_heading = x_.z() - 0.5 * input.increment.y();  // x_ is already predicted
  const Eigen::Vector2d across(-std::sin(mid_heading), std::cos(mid_heading));
  P_pp->topLeftCorner<2, 2>().noalias() += input.lateral_variance_m2 * across * across.transpose();
}

void SlamState::Predict(const MotionInput& input, double a_m) {
  if (calibrated()) {
    PredictCalibrated(input, a_m);
    return;
  }
  Eigen::Matrix<double, 3, 2> W;
  const Eigen::Matrix3d A = MovePose(input, a_m, &W);

  // Pose block: A P_pp A^T + W Q W^T, symmetrised exactly.
  const Eigen::Matrix3d P_pp = P_.topLeftCorner<3, 3>();
  Eigen::Matrix3d P_pp_new;
  P_pp_new.noalias() = A * P_pp * A.transpose();
  P_pp_new.noalias() += W * input.covariance * W.transpose();
  AddLateralSlip(input, &P_pp_new);
  P_.topLeftCorner<3, 3>() = 0.5 * (P_pp_new + P_pp_new.transpose());

  // Cross terms P_fp <- P_fp A^T. A is the identity but for (0,2) and (1,2),
  // so only the x and y columns change: contiguous, O(n).
  const int m = n_ - 3;
  if (m == 0) return;
  P_.col(0).segment(3, m) += A(0, 2) * P_.col(2).segment(3, m);
  P_.col(1).segment(3, m) += A(1, 2) * P_.col(2).segment(3, m);
  // Mirror into the pose rows, the same values (P stays exactly symmetric).
  P_.block(0, 3, 3, m) = P_.block(3, 0, m, 3).transpose();
}

void SlamState::PredictCalibrated(const MotionInput& raw, double a_m) {
  // The increment corrected by the odometry's estimated errors, and its
  // derivatives by the raw increment (D) and by (q_d, q_th, k) (C).
  const double d = raw.increment.x();
  const double dth = raw.increment.y();
  const double q_d = x_[kDistanceScale];
  const double q_th = x_[kHeadingScale];
  const double k = x_[kHeadingPerMetre];
  const double quarter_track2 = 0.25 * raw.axle_track_m * raw.axle_track_m;
  MotionInput input = raw;
  input.increment = Eigen::Vector2d((1.0 + q_d) * d + k * quarter_track2 * dth,
                                    (1.0 + q_th) * dth + k * d);
  Eigen::Matrix2d D;
  D << 1.0 + q_d, k * quarter_track2, k, 1.0 + q_th;
  input.covariance = D * raw.covariance * D.transpose();
  const Eigen::Vector2d at = raw.calibration_jacobian_increment.value_or(raw.increment);
  Eigen::Matrix<double, 2, 3> C;
  C << at.x(), 0.0, quarter_track2 * at.y(), 0.0, at.y(), at.x();

  Eigen::Matrix<double, 3, 2> W;
  const Eigen::Matrix3d A = MovePose(input, a_m, &W);
  // B = d pose' / d (q_d, q_th, k), at state indices 3-5.
  const Eigen::Matrix3d B = W * C;

  // The pose is p' = A p + B q + noise: every row r of P gets
  // P_rp' = P_rp A^T + P_rq B^T (T below, from the old values), and the
  // pose block A T_p + B T_q + W Q W^T.
  const int n = n_;
  Eigen::MatrixXd T(n, 3);
  T.noalias() = P_.block(0, 0, n, 3) * A.transpose();
  T.noalias() += P_.block(0, kDistanceScale, n, 3) * B.transpose();
  Eigen::Matrix3d P_pp_new;
  P_pp_new.noalias() = A * T.topRows<3>();
  P_pp_new.noalias() += B * T.middleRows<3>(kDistanceScale);
  P_pp_new.noalias() += W * input.covariance * W.transpose();
  AddLateralSlip(input, &P_pp_new);
  P_.block(3, 0, n - 3, 3) = T.bottomRows(n - 3);
  P_.block(0, 3, 3, n - 3) = T.bottomRows(n - 3).transpose();
  P_.topLeftCorner<3, 3>() = 0.5 * (P_pp_new + P_pp_new.transpose());
  AddCalibrationDrift(raw);
}

void SlamState::AddCalibrationDrift(const MotionInput& raw) {
  if (raw.wheel_slip_drift_per_m <= 0.0) return;
  // The wheels' travel, and the random walk of the slips' mean (q_d, q_th)
  // and difference over the track (k), on the entries that are estimated.
  const double half_track = 0.5 * raw.axle_track_m;
  const double d = raw.increment.x();
  const double dth = raw.increment.y();
  const double travel = std::abs(d - half_track * dth) + std::abs(d + half_track * dth);
  const double variance = raw.wheel_slip_drift_per_m * travel;
  const bool q_d = calibration_std_[0] > 0.0;
  const bool q_th = calibration_std_[1] > 0.0;
  if (q_d) P_(kDistanceScale, kDistanceScale) += 0.25 * variance;
  if (q_th) P_(kHeadingScale, kHeadingScale) += 0.25 * variance;
  if (q_d && q_th) {
    P_(kDistanceScale, kHeadingScale) += 0.25 * variance;
    P_(kHeadingScale, kDistanceScale) += 0.25 * variance;
  }
  if (calibration_std_[2] > 0.0) {
    P_(kHeadingPerMetre, kHeadingPerMetre) += variance / (raw.axle_track_m * raw.axle_track_m);
  }
}

bool SlamState::PredictWithJacobians(int k, Eigen::Vector2d* h,
                                     Eigen::Matrix<double, 2, 3>* H_pose,
                                     Eigen::Matrix2d* H_feature) const {
  const int j = FeatureIndex(k);
  auto corner_on_sensor = [&](const Eigen::VectorXd& xi) {
    return types_[k] == FeatureType::kCorner &&
           (xi.segment<2>(j) - SensorPose(xi.head<3>(), X_RS_).head<2>()).norm() <=
               kMinCornerRange;
  };
  if (corner_on_sensor(x_)) return false;
  if (jacobians_ == JacobianPoint::kCurrent) {
    *h = PredictObservation(types_[k], pose(), feature(k), X_RS_, H_pose, H_feature);
    return true;
  }
  if (corner_on_sensor(x_first_)) return false;
  *h = PredictObservation(types_[k], pose(), feature(k), X_RS_);
  Eigen::Vector2d h_first = PredictObservation(types_[k], x_first_.head<3>(),
                                               x_first_.segment<2>(j), X_RS_, H_pose, H_feature);
  // The Jacobians in h's polar form (a line's canonical form may differ at
  // the two points).
  if (types_[k] == FeatureType::kLine) AlignLineToObservation(*h, &h_first, H_pose, H_feature);
  return true;
}

SlamState::Measurement SlamState::Measure(int k) const {
  MJSLAM_CHECK(k >= 0 && k < num_features());
  Measurement m;
  if (!PredictWithJacobians(k, &m.h, &m.H_pose, &m.H_feature)) return m;

  // H P H^T over the 5x5 block of the pose and the feature.
  Eigen::Matrix<double, 2, 5> H;
  H << m.H_pose, m.H_feature;
  const Eigen::Matrix<double, 5, 5> P_block = JointCovariance(k);
  Eigen::Matrix2d HPHt;
  HPHt.noalias() = H * P_block * H.transpose();
  m.HPHt = 0.5 * (HPHt + HPHt.transpose());
  if (calibrated()) {
    const int j = FeatureIndex(k);
    m.HP_laser.noalias() = m.H_pose * P_.block<3, 2>(0, kRangeBias);
    m.HP_laser.noalias() += m.H_feature * P_.block<2, 2>(j, kRangeBias);
  }
  m.valid = true;
  return m;
}

void SlamState::ToObservation(FeatureType type, const Eigen::Vector2d& z,
                              const Eigen::Vector2d& range_bias_gradient, Measurement* m) const {
  if (!m->valid) return;
  if (type == FeatureType::kLine &&
      AlignLineToObservation(z, &m->h, &m->H_pose, &m->H_feature, &m->HPHt)) {
    m->HP_laser.row(0) *= -1.0;
  }
  if (!calibrated()) return;
  // h + E (b, s); H P H^T + HP_l E^T + E HP_l^T + E P_ll E^T.
  const Eigen::Matrix2d E = LaserErrorJacobian(z, range_bias_gradient);
  m->h += E * x_.segment<2>(kRangeBias);
  Eigen::Matrix2d cross;
  cross.noalias() = m->HP_laser * E.transpose();
  Eigen::Matrix2d HPHt = m->HPHt + cross + cross.transpose();
  HPHt.noalias() += E * P_.block<2, 2>(kRangeBias, kRangeBias) * E.transpose();
  m->HPHt = 0.5 * (HPHt + HPHt.transpose());
}

SlamState::Measurement SlamState::MeasureFor(int k, const Eigen::Vector2d& z,
                                             const Eigen::Vector2d& range_bias_gradient) const {
  Measurement m = Measure(k);
  ToObservation(types_[k], z, range_bias_gradient, &m);
  return m;
}

Eigen::Matrix2d SlamState::InnovationCovariance(int k, const Eigen::Vector2d& z,
                                                const Eigen::Matrix2d& R,
                                                const Eigen::Vector2d& range_bias_gradient) const {
  const Measurement m = MeasureFor(k, z, range_bias_gradient);
  MJSLAM_CHECK(m.valid);
  return m.HPHt + R;
}

void SlamState::Reserve(int n) {
  if (n <= P_.cols()) return;
  const int capacity = PaddedSize(std::max(n, 2 * static_cast<int>(P_.cols())));
  Eigen::MatrixXd grown = Eigen::MatrixXd::Zero(capacity, capacity);
  grown.topLeftCorner(n_, n_) = P_.topLeftCorner(n_, n_);
  P_.swap(grown);
  scratch_ = Eigen::MatrixXd::Zero(capacity, 2);
}

int SlamState::AddFeature(FeatureType type, const Eigen::Vector2d& z_observed,
                          const Eigen::Matrix2d& R, const Eigen::Vector2d& range_bias_gradient) {
  // With self-calibration, the observation less the laser's estimated errors.
  Eigen::Matrix2d E = Eigen::Matrix2d::Zero();
  Eigen::Vector2d z = z_observed;
  if (calibrated()) {
    E = LaserErrorJacobian(z_observed, range_bias_gradient);
    z -= E * x_.segment<2>(kRangeBias);
  }
  // Inverse observation model and its Jacobians at the current pose.
  Eigen::Matrix<double, 2, 3> G_pose;
  Eigen::Matrix2d G_z;
  const Eigen::Vector2d f = InitializeFeature(type, pose(), z, X_RS_, &G_pose, &G_z);
  if (jacobians_ == JacobianPoint::kFirstEstimates) {
    // G_pose at the pose's linearisation point and the feature's first
    // estimate f: that of the observation z' = h(pose_lin, f), for which the
    // inverse model gives f from pose_lin. Then G_pose carries the global
    // translation and rotation of the pose over to f, as the FEJ H do.
    const Eigen::Vector3d pose_lin = x_first_.head<3>();
    const bool on_sensor = type == FeatureType::kCorner &&
                           (f - SensorPose(pose_lin, X_RS_).head<2>()).norm() <= kMinCornerRange;
    if (!on_sensor) {
      const Eigen::Vector2d z_lin = PredictObservation(type, pose_lin, f, X_RS_);
      InitializeFeature(type, pose_lin, z_lin, X_RS_, &G_pose, nullptr);
    }
  }

  const int j = n_;
  Reserve(n_ + 2);

  // Cross-covariance with everything so far: P_fx = G_pose P_px. By symmetry
  // P_px^T is the first three columns, so the new columns are contiguous.
  // With self-calibration also G_l P_lx, G_l = -G_z E on the laser's (b, s).
  P_.block(0, j, n_, 2).noalias() = P_.block(0, 0, n_, 3) * G_pose.transpose();
  Eigen::Matrix2d G_laser = Eigen::Matrix2d::Zero();
  if (calibrated()) {
    G_laser = -G_z * E;
    P_.block(0, j, n_, 2).noalias() += P_.block(0, kRangeBias, n_, 2) * G_laser.transpose();
  }
  P_.block(j, 0, 2, n_) = P_.block(0, j, n_, 2).transpose();

  // The feature's own block.
  const Eigen::Matrix3d P_pp = P_.topLeftCorner<3, 3>();
  Eigen::Matrix2d P_ff;
  if (calibrated()) {
    // G_v P_vv G_v^T over the pose and (b, s): P_fx's rows there, times G_v^T.
    P_ff.noalias() = P_.block<2, 3>(j, 0) * G_pose.transpose();
    P_ff.noalias() += P_.block<2, 2>(j, kRangeBias) * G_laser.transpose();
  } else {
    P_ff.noalias() = G_pose * P_pp * G_pose.transpose();
  }
  P_ff.noalias() += G_z * R * G_z.transpose();
  P_.block<2, 2>(j, j) = 0.5 * (P_ff + P_ff.transpose());

  return Append(type, f);
}

int SlamState::AddLineIntersection(int a, int b) {
  MJSLAM_CHECK(a >= 0 && a < num_features() && b >= 0 && b < num_features() && a != b);
  MJSLAM_CHECK(types_[a] == FeatureType::kLine && types_[b] == FeatureType::kLine);
  Eigen::Matrix<double, 2, 4> J;
  const Eigen::Vector2d f = IntersectLines(feature(a), feature(b), &J);
  const int ia = FeatureIndex(a);
  const int ib = FeatureIndex(b);

  const int j = n_;
  Reserve(n_ + 2);

  // Cross-covariance with everything so far, P_fx = J P_(ab)x, written as
  // columns (P symmetric): P_xf = P_x(ab) J^T.
  P_.block(0, j, n_, 2).noalias() = P_.block(0, ia, n_, 2) * J.leftCols<2>().transpose();
  P_.block(0, j, n_, 2).noalias() += P_.block(0, ib, n_, 2) * J.rightCols<2>().transpose();
  P_.block(j, 0, 2, n_) = P_.block(0, j, n_, 2).transpose();

  // The feature's own block, J P_(ab)(ab) J^T = P_f(ab) J^T.
  Eigen::Matrix2d P_ff;
  P_ff.noalias() = P_.block<2, 2>(j, ia) * J.leftCols<2>().transpose();
  P_ff.noalias() += P_.block<2, 2>(j, ib) * J.rightCols<2>().transpose();
  P_.block<2, 2>(j, j) = 0.5 * (P_ff + P_ff.transpose());

  return Append(FeatureType::kCorner, f);
}

void SlamState::RemoveFeature(int k) {
  MJSLAM_CHECK(k >= 0 && k < num_features());
  const int j = FeatureIndex(k);
  const int tail = n_ - j - 2;
  if (tail > 0) {
    P_.block(j, 0, tail, n_) = P_.block(j + 2, 0, tail, n_).eval();
    P_.block(0, j, n_ - 2, tail) = P_.block(0, j + 2, n_ - 2, tail).eval();
    x_.segment(j, tail) = x_.segment(j + 2, tail).eval();
    if (jacobians_ == JacobianPoint::kFirstEstimates) {
      x_first_.segment(j, tail) = x_first_.segment(j + 2, tail).eval();
    }
  }
  // The freed rows and columns are left zero, as Reserve leaves new ones.
  P_.block(n_ - 2, 0, 2, n_).setZero();
  P_.block(0, n_ - 2, n_, 2).setZero();
  x_.conservativeResize(n_ - 2);
  if (jacobians_ == JacobianPoint::kFirstEstimates) x_first_.conservativeResize(n_ - 2);
  types_.erase(types_.begin() + k);
  n_ -= 2;
}

int SlamState::Append(FeatureType type, const Eigen::Vector2d& f) {
  x_.conservativeResize(n_ + 2);
  x_.segment<2>(n_) = f;
  if (jacobians_ == JacobianPoint::kFirstEstimates) {
    x_first_.conservativeResize(n_ + 2);
    x_first_.segment<2>(n_) = f;
  }
  types_.push_back(type);
  n_ += 2;
  return num_features() - 1;
}

Eigen::Vector2d SlamState::WhitenedGain(int j, const Eigen::Matrix<double, 2, 3>& H_pose,
                                        const Eigen::Matrix2d& H_feature,
                                        const Eigen::Matrix2d& E, const Eigen::Matrix2d& R,
                                        const Eigen::Vector2d& nu) {
  const int n = n_;
  const Eigen::Index stride = P_.outerStride();
  const double* p0 = P_.data();
  const double* p1 = p0 + stride;
  const double* p2 = p1 + stride;
  const double* pj = p0 + j * stride;
  const double* pj1 = pj + stride;
  double* u0 = scratch_.data();
  double* u1 = u0 + scratch_.outerStride();

  // U = P H^T from the 5 columns of P that H touches.
  for (int r = 0; r < n; ++r) {
    u0[r] = H_pose(0, 0) * p0[r] + H_pose(0, 1) * p1[r] + H_pose(0, 2) * p2[r] +
            H_feature(0, 0) * pj[r] + H_feature(0, 1) * pj1[r];
    u1[r] = H_pose(1, 0) * p0[r] + H_pose(1, 1) * p1[r] + H_pose(1, 2) * p2[r] +
            H_feature(1, 0) * pj[r] + H_feature(1, 1) * pj1[r];
  }

  // S = H U + R, from U's pose and feature rows.
  Eigen::Matrix<double, 5, 2> U_block;
  U_block << u0[0], u1[0], u0[1], u1[1], u0[2], u1[2], u0[j], u1[j], u0[j + 1], u1[j + 1];
  Eigen::Matrix<double, 2, 5> H;
  H << H_pose, H_feature;
  Eigen::Matrix2d S;
  S.noalias() = H * U_block;
  if (calibrated()) {
    // With self-calibration H also has E on the laser's (b, s): U gains
    // P_.l E^T, and S = [H E] [U; U_l], with U_l the (b, s) rows of the new U.
    const double* pb = p0 + kRangeBias * stride;
    const double* ps = pb + stride;
    for (int r = 0; r < n; ++r) {
      u0[r] += E(0, 0) * pb[r] + E(0, 1) * ps[r];
      u1[r] += E(1, 0) * pb[r] + E(1, 1) * ps[r];
    }
    U_block << u0[0], u1[0], u0[1], u1[1], u0[2], u1[2], u0[j], u1[j], u0[j + 1], u1[j + 1];
    Eigen::Matrix2d U_laser;
    U_laser << u0[kRangeBias], u1[kRangeBias], u0[kRangeScale], u1[kRangeScale];
    S.noalias() = H * U_block;
    S.noalias() += E * U_laser;
  }
  S += R;
  S = 0.5 * (S + S.transpose());

  // S = L L^T (2x2 Cholesky).
  MJSLAM_CHECK(S(0, 0) > 0.0);
  const double l11 = std::sqrt(S(0, 0));
  const double l21 = S(1, 0) / l11;
  const double schur = S(1, 1) - l21 * l21;
  MJSLAM_CHECK(schur > 0.0);
  const double l22 = std::sqrt(schur);

  // V = U L^-T in place, so that K S K^T = V V^T and K nu = V L^-1 nu.
  const double inv_l11 = 1.0 / l11;
  const double inv_l22 = 1.0 / l22;
  for (int r = 0; r < n; ++r) {
    const double v0 = u0[r] * inv_l11;
    u0[r] = v0;
    u1[r] = (u1[r] - l21 * v0) * inv_l22;
  }
  const double w0 = nu.x() * inv_l11;
  const double w1 = (nu.y() - l21 * w0) * inv_l22;
  return Eigen::Vector2d(w0, w1);
}

void SlamState::ApplyGain(const Eigen::Vector2d& w) {
  const int n = n_;
  const Eigen::Index stride = P_.outerStride();
  const double* u0 = scratch_.data();
  const double* u1 = u0 + scratch_.outerStride();
  const double w0 = w.x();
  const double w1 = w.y();

  // Mean: xi <- xi + K nu.
  double* x = x_.data();
  for (int r = 0; r < n; ++r) x[r] += u0[r] * w0 + u1[r] * w1;

  // Covariance: P <- P - V V^T, two columns per sweep so that V is read once
  // per pair. Element (r, c) is P(r, c) - fma(v0[r], v0[c], v1[r] v1[c]) and
  // element (c, r) multiplies the same numbers, so P stays exactly symmetric.
  double* P = P_.data();
  int c = 0;
  for (; c + 1 < n; c += 2) {
    double* col_a = P + c * stride;
    double* col_b = col_a + stride;
    const double a0 = u0[c];
    const double a1 = u1[c];
    const double b0 = u0[c + 1];
    const double b1 = u1[c + 1];
    for (int r = 0; r < n; ++r) {
      const double v0 = u0[r];
      const double v1 = u1[r];
      col_a[r] -= std::fma(v0, a0, v1 * a1);
      col_b[r] -= std::fma(v0, b0, v1 * b1);
    }
  }
  for (; c < n; ++c) {
    double* col = P + c * stride;
    const double a0 = u0[c];
    const double a1 = u1[c];
    for (int r = 0; r < n; ++r) col[r] -= std::fma(u0[r], a0, u1[r] * a1);
  }
}

void SlamState::WrapAngles() {
  double* x = x_.data();
  x_.z() = WrapAngleFast(x_.z());
  for (int f = 0; f < num_features(); ++f) {
    if (types_[f] != FeatureType::kLine) continue;
    double& al = x[FeatureIndex(f) + 1];
    al = WrapAngleFast(al);
  }
}

void SlamState::Update(int k, const Eigen::Vector2d& z, const Eigen::Matrix2d& R,
                       const Eigen::Vector2d& range_bias_gradient) {
  MJSLAM_CHECK(k >= 0 && k < num_features());
  // The prediction, its Jacobians and the innovation.
  Eigen::Matrix<double, 2, 3> H_pose;
  Eigen::Matrix2d H_feature;
  Eigen::Vector2d h;
  MJSLAM_CHECK(PredictWithJacobians(k, &h, &H_pose, &H_feature));
  if (types_[k] == FeatureType::kLine) AlignLineToObservation(z, &h, &H_pose, &H_feature);
  Eigen::Matrix2d E = Eigen::Matrix2d::Zero();
  if (calibrated()) {
    E = LaserErrorJacobian(z, range_bias_gradient);
    h += E * x_.segment<2>(kRangeBias);
  }
  const Eigen::Vector2d nu = Innovation(z, h);

  // The correction, then the angles back into (-pi, pi].
  const Eigen::Vector2d w = WhitenedGain(FeatureIndex(k), H_pose, H_feature, E, R, nu);
  ApplyGain(w);
  WrapAngles();
}

}  // namespace mjslam::slam
