#include "slam/observation_models.h"

#include <cmath>

#include "common/angles.h"
#include "common/check.h"
#include "slam/fast_wrap.h"

namespace mjslam::slam {

Eigen::Vector3d SensorPose(const Eigen::Vector3d& pose_WR, const Pose2& X_RS,
                           Eigen::Matrix3d* J) {
  const double c = std::cos(pose_WR.z());
  const double s = std::sin(pose_WR.z());
  // X_WS = X_WR * X_RS, with the rotated mount offset.
  const double dx_W = c * X_RS.x - s * X_RS.y;
  const double dy_W = s * X_RS.x + c * X_RS.y;
  if (J != nullptr) {
    *J << 1.0, 0.0, -dy_W,
          0.0, 1.0, dx_W,
          0.0, 0.0, 1.0;
  }
  return {pose_WR.x() + dx_W, pose_WR.y() + dy_W, WrapAngleFast(pose_WR.z() + X_RS.theta)};
}

Eigen::Vector2d CanonicalLine(const Eigen::Vector2d& line, Eigen::Matrix2d* J) {
  const bool flip = line.x() < 0.0;
  if (J != nullptr) {
    *J << (flip ? -1.0 : 1.0), 0.0,
          0.0, 1.0;
  }
  if (flip) return {-line.x(), WrapAngleFast(line.y() + kPi)};
  return {line.x(), WrapAngleFast(line.y())};
}

Eigen::Vector2d PredictLine(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& line_W,
                            const Pose2& X_RS, Eigen::Matrix<double, 2, 3>* H_pose,
                            Eigen::Matrix2d* H_feature) {
  Eigen::Matrix3d J_sensor;
  const Eigen::Vector3d pose_WS = SensorPose(pose_WR, X_RS, &J_sensor);
  const double r = line_W.x();
  const double al = line_W.y();
  const double c = std::cos(al);
  const double s = std::sin(al);

  // Eq. (8) for the sensor pose, before canonicalisation.
  const Eigen::Vector2d raw(r - pose_WS.x() * c - pose_WS.y() * s, al - pose_WS.z());
  Eigen::Matrix2d J_canonical;
  const Eigen::Vector2d z = CanonicalLine(raw, &J_canonical);

  if (H_pose != nullptr) {
    Eigen::Matrix<double, 2, 3> H_sensor;
    H_sensor << -c, -s, 0.0,
                0.0, 0.0, -1.0;
    H_pose->noalias() = J_canonical * H_sensor * J_sensor;
  }
  if (H_feature != nullptr) {
    Eigen::Matrix2d H_raw;
    H_raw << 1.0, pose_WS.x() * s - pose_WS.y() * c,
             0.0, 1.0;
    H_feature->noalias() = J_canonical * H_raw;
  }
  return z;
}

Eigen::Vector2d PredictCorner(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& p_WC,
                              const Pose2& X_RS, Eigen::Matrix<double, 2, 3>* H_pose,
                              Eigen::Matrix2d* H_feature) {
  Eigen::Matrix3d J_sensor;
  const Eigen::Vector3d pose_WS = SensorPose(pose_WR, X_RS, &J_sensor);
  const double dx = p_WC.x() - pose_WS.x();
  const double dy = p_WC.y() - pose_WS.y();
  const double q = dx * dx + dy * dy;
  MJSLAM_CHECK(q > 0.0);
  const double range = std::sqrt(q);

  // Eq. (7) for the sensor pose.
  const Eigen::Vector2d z(range, WrapAngleFast(std::atan2(dy, dx) - pose_WS.z()));
  if (H_pose != nullptr) {
    Eigen::Matrix<double, 2, 3> H_sensor;
    H_sensor << -dx / range, -dy / range, 0.0,
                dy / q, -dx / q, -1.0;
    H_pose->noalias() = H_sensor * J_sensor;
  }
  if (H_feature != nullptr) {
    *H_feature << dx / range, dy / range,
                  -dy / q, dx / q;
  }
  return z;
}

Eigen::Vector2d InitializeLine(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& z,
                               const Pose2& X_RS, Eigen::Matrix<double, 2, 3>* G_pose,
                               Eigen::Matrix2d* G_z) {
  Eigen::Matrix3d J_sensor;
  const Eigen::Vector3d pose_WS = SensorPose(pose_WR, X_RS, &J_sensor);
  const double al = z.y() + pose_WS.z();
  const double c = std::cos(al);
  const double s = std::sin(al);
  // d r / d al at fixed sensor position.
  const double dr_dal = -pose_WS.x() * s + pose_WS.y() * c;

  // Eq. (8) solved for (r, al), then canonicalised.
  const Eigen::Vector2d raw(z.x() + pose_WS.x() * c + pose_WS.y() * s, al);
  Eigen::Matrix2d J_canonical;
  const Eigen::Vector2d line = CanonicalLine(raw, &J_canonical);

  if (G_pose != nullptr) {
    Eigen::Matrix<double, 2, 3> G_sensor;
    G_sensor << c, s, dr_dal,
                0.0, 0.0, 1.0;
    G_pose->noalias() = J_canonical * G_sensor * J_sensor;
  }
  if (G_z != nullptr) {
    Eigen::Matrix2d G_raw;
    G_raw << 1.0, dr_dal,
             0.0, 1.0;
    G_z->noalias() = J_canonical * G_raw;
  }
  return line;
}

Eigen::Vector2d InitializeCorner(const Eigen::Vector3d& pose_WR, const Eigen::Vector2d& z,
                                 const Pose2& X_RS, Eigen::Matrix<double, 2, 3>* G_pose,
                                 Eigen::Matrix2d* G_z) {
  Eigen::Matrix3d J_sensor;
  const Eigen::Vector3d pose_WS = SensorPose(pose_WR, X_RS, &J_sensor);
  const double phi = z.y() + pose_WS.z();
  const double c = std::cos(phi);
  const double s = std::sin(phi);
  const double range = z.x();

  // Eq. (7) solved for the corner.
  const Eigen::Vector2d p_WC(pose_WS.x() + range * c, pose_WS.y() + range * s);
  if (G_pose != nullptr) {
    Eigen::Matrix<double, 2, 3> G_sensor;
    G_sensor << 1.0, 0.0, -range * s,
                0.0, 1.0, range * c;
    G_pose->noalias() = G_sensor * J_sensor;
  }
  if (G_z != nullptr) {
    *G_z << c, -range * s,
            s, range * c;
  }
  return p_WC;
}

bool AlignLineToObservation(const Eigen::Vector2d& z, Eigen::Vector2d* h,
                            Eigen::Matrix<double, 2, 3>* H_pose, Eigen::Matrix2d* H_feature,
                            Eigen::Matrix2d* HPHt) {
  if (std::abs(WrapAngleFast(z.y() - h->y())) <= kPi / 2.0) return false;
  *h = Eigen::Vector2d(-h->x(), WrapAngleFast(h->y() + kPi));
  if (H_pose != nullptr) H_pose->row(0) *= -1.0;
  if (H_feature != nullptr) H_feature->row(0) *= -1.0;
  if (HPHt != nullptr) {
    (*HPHt)(0, 1) = -(*HPHt)(0, 1);
    (*HPHt)(1, 0) = -(*HPHt)(1, 0);
  }
  return true;
}

Eigen::Vector2d PredictObservation(FeatureType type, const Eigen::Vector3d& pose_WR,
                                   const Eigen::Vector2d& feature, const Pose2& X_RS,
                                   Eigen::Matrix<double, 2, 3>* H_pose,
                                   Eigen::Matrix2d* H_feature) {
  if (type == FeatureType::kLine) return PredictLine(pose_WR, feature, X_RS, H_pose, H_feature);
  return PredictCorner(pose_WR, feature, X_RS, H_pose, H_feature);
}

Eigen::Vector2d InitializeFeature(FeatureType type, const Eigen::Vector3d& pose_WR,
                                  const Eigen::Vector2d& z, const Pose2& X_RS,
                                  Eigen::Matrix<double, 2, 3>* G_pose, Eigen::Matrix2d* G_z) {
  if (type == FeatureType::kLine) return InitializeLine(pose_WR, z, X_RS, G_pose, G_z);
  return InitializeCorner(pose_WR, z, X_RS, G_pose, G_z);
}

}  // namespace mjslam::slam
