#pragma once

#include <Eigen/Core>

#include "common/angles.h"
#include "common/map_feature.h"
#include "common/pose2.h"
#include "slam/fast_wrap.h"

namespace mjslam::slam {

/// Observation models of the paper (Eqs. 7 and 8), composed with the laser
/// mount: the models are written for the sensor frame S, whose pose is
/// X_WS = X_WR * X_RS. Each returns its prediction and, when the pointers are
/// not null, its Jacobians in the same call (GTSAM style). Poses of R are the
/// state's (x, y, th) in W; angles in radians, lengths in metres.

/// The pose (x_s, y_s, th_s) of S in W from the pose of R; `J` receives
/// d(x_s, y_s, th_s) / d(x, y, th).
Eigen::Vector3d SensorPose(const Eigen::Vector3d& pose_WR, const Pose2& X_RS,
                           Eigen::Matrix3d* J = nullptr);

/// The canonical form of a polar line (rho, alpha): (-rho, alpha + pi) when
/// rho < 0, the same line otherwise; alpha wrapped to (-pi, pi]. `J` receives
/// the Jacobian of the change, diag(-1, 1) or the identity.
Eigen::Vector2d CanonicalLine(const Eigen::Vector2d& line, Eigen::Matrix2d* J = nullptr);

/// Eq. (8): the line feature (r, al) in W seen from S as (rho, alpha),
/// rho = r - x_s cos al - y_s sin al, alpha = al - th_s, in canonical form
/// (rho >= 0; the flip negates the rho row of the Jacobians). `H_pose` is
/// d z / d(x, y, th) of R, `H_feature` d z / d(r, al).
Eigen::Vector2d PredictLine(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& line_W,
                            const Pose2& X_RS, Eigen::Matrix<double, 2, 3>* H_pose = nullptr,
                            Eigen::Matrix2d* H_feature = nullptr);

/// Eq. (7): the corner p_WC seen from S as (range, bearing),
/// range = |p_WC - p_WS|, bearing = atan2(...) - th_s wrapped. `H_pose` is
/// d z / d(x, y, th) of R, `H_feature` d z / d p_WC. Precondition (checked):
/// the corner is not at the sensor's position.
Eigen::Vector2d PredictCorner(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& p_WC,
                              const Pose2& X_RS, Eigen::Matrix<double, 2, 3>* H_pose = nullptr,
                              Eigen::Matrix2d* H_feature = nullptr);

/// Inverse of Eq. (8): the line (r, al) in W, canonical, from an observation
/// z = (rho, alpha) in S. `G_pose` is d(r, al) / d(x, y, th) of R and `G_z`
/// d(r, al) / d z: the Jacobians of the state augmentation.
Eigen::Vector2d InitializeLine(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& z,
                               const Pose2& X_RS, Eigen::Matrix<double, 2, 3>* G_pose = nullptr,
                               Eigen::Matrix2d* G_z = nullptr);

/// Inverse of Eq. (7): the corner p_WC from an observation z = (range,
/// bearing) in S. `G_pose` is d p_WC / d(x, y, th) of R and `G_z` d p_WC / d z.
Eigen::Vector2d InitializeCorner(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& z,
                                 const Pose2& X_RS, Eigen::Matrix<double, 2, 3>* G_pose = nullptr,
                                 Eigen::Matrix2d* G_z = nullptr);

/// Dispatches to PredictLine or PredictCorner.
Eigen::Vector2d PredictObservation(FeatureType type, const Eigen::Vector3d& pose_WR,
                                   const Eigen::Vector2d& feature, const Pose2& X_RS,
                                   Eigen::Matrix<double, 2, 3>* H_pose = nullptr,
                                   Eigen::Matrix2d* H_feature = nullptr);

/// Dispatches to InitializeLine or InitializeCorner.
Eigen::Vector2d InitializeFeature(FeatureType type, const Eigen::Vector3d& pose_WR,
                                  const Eigen::Vector2d& z, const Pose2& X_RS,
                                  Eigen::Matrix<double, 2, 3>* G_pose = nullptr,
                                  Eigen::Matrix2d* G_z = nullptr);

/// Puts a line prediction h (with its Jacobians, when not null) in the polar
/// form of the observation z it is compared with: if their alphas differ by
/// more than pi/2, h becomes the same line's other form (-rho, alpha + pi)
/// and the rho rows of `H_pose`, `H_feature` and the sign of the off-diagonal
/// of `HPHt` (H P H^T) change. Returns whether it flipped.
///
/// Why: canonical forms (rho >= 0) jump by pi in alpha when the sensor
/// crosses the line (rho = 0); a sensor near a wall's extension can see the
/// line on one side while the estimate puts it on the other. Differencing the
/// aligned forms is continuous there; away from rho = 0 it is exactly the
/// canonical difference (docs/method.md, departure 4; both forms then agree within pi/2).
bool AlignLineToObservation(const Eigen::Vector2d& z, Eigen::Vector2d* h,
                            Eigen::Matrix<double, 2, 3>* H_pose = nullptr,
                            Eigen::Matrix2d* H_feature = nullptr,
                            Eigen::Matrix2d* HPHt = nullptr);

/// The innovation z - h of either model: the first components subtracted,
/// the second (an angle) subtracted and wrapped to (-pi, pi]. A line's h must
/// be in z's polar form (AlignLineToObservation).
inline Eigen::Vector2d Innovation(const Eigen::Vector2d& z, const Eigen::Vector2d& h) {
  return {z.x() - h.x(), WrapAngleFast(z.y() - h.y())};
}

}  // namespace mjslam::slam
