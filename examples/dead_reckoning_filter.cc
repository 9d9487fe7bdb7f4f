// Bring your own filter: a dead-reckoning estimator, written against the
// filter interface of slam/filter.h and run by the closed loop beside the
// paper's two EKFs (examples/dead_reckoning.yaml).
//
// A filter is one class and one registration. The closed loop
// (app::FilterBank) builds every filter of `slam.filters` through the
// registry by its `kind`, hands each the same records and the features
// extracted once per scan, times its Step, and writes its columns of
// trajectory.csv (`<name>_x`, ...), its map_<name>.csv and its summary.json
// entry by its name. Nothing in app/ changes for a new kind.
//
// This one ignores the scans: it integrates the wheel odometry with the
// paper's motion model (Eq. 6) and propagates the pose covariance, as the
// EKF's prediction does (without its skid and lateral slip terms), without
// ever correcting. Its NEES in
// trajectory.csv shows whether the odometry noise model is honest; its
// error, how far the robot drifts without SLAM.
#include <cmath>
#include <memory>
#include <utility>
#include <variant>
#include <vector>

// The interface (slam::Filter), the registry and the settings.
#include "slam/filter.h"
// The motion model the EKFs use: OdometryInput turns two odometry poses into
// the input (d, dth) with its covariance, PredictPose integrates Eq. (6) and
// gives its Jacobians A (by the pose) and W (by the input).
#include "slam/motion_model.h"

namespace mjslam::examples {
namespace {

class DeadReckoningFilter : public slam::Filter {
 public:
  // The factory's arguments: the entry's settings (slam.ekf with the entry's
  // own keys applied), the known start pose of R and the laser mount (unused:
  // no scans), and a stream of its own (unused: nothing random).
  DeadReckoningFilter(const slam::FilterSettings& settings, const Pose2& X_WR0)
      : a_m_(settings.slam.ekf.control_point_offset_m),
        pose_(X_WR0.x, X_WR0.y, X_WR0.theta) {
    // The odometry noise of slam.ekf's process model when it is of kind
    // odometry, else the built-in values.
    if (const auto* model =
            std::get_if<slam::OdometryProcessModel>(&settings.slam.ekf.process_model)) {
      noise_ = model->noise;
    }
    // Known start, as the EKFs' (slam.ekf.initial_*_std).
    P_.setZero();
    P_(0, 0) = P_(1, 1) = std::pow(settings.slam.ekf.initial_position_std_m, 2);
    P_(2, 2) = std::pow(settings.slam.ekf.initial_heading_std_rad, 2);
  }

  slam::StepReport Step(const SensorRecord& record, const slam::ScanFeatures*) override {
    // The increment since the last record and its covariance Q. The first
    // record is the odometry's reference: no motion (its noise floor still
    // enters, as in the EKF).
    const Pose2& X_OR_previous = has_previous_ ? X_OR_previous_ : record.X_OR;
    const slam::MotionInput input = slam::OdometryInput(X_OR_previous, record.X_OR, a_m_, noise_);
    // pose' = f(pose, u); P' = A P A^T + W Q W^T.
    Eigen::Matrix3d A;
    Eigen::Matrix<double, 3, 2> W;
    pose_ = slam::PredictPose(pose_, input.increment, a_m_, &A, &W);
    P_ = A * P_ * A.transpose() + W * input.covariance * W.transpose();
    X_OR_previous_ = record.X_OR;
    has_previous_ = true;
    // No map, no matches: only the map size (0) is reported.
    return slam::StepReport();
  }

  Pose2 X_WR() const override { return Pose2(pose_(0), pose_(1), pose_(2)); }
  Eigen::Matrix3d pose_covariance() const override { return P_; }
  std::vector<MapFeature> Map() const override { return {}; }
  int num_features() const override { return 0; }

 private:
  double a_m_;
  slam::OdometryNoiseParams noise_;
  Eigen::Vector3d pose_;
  Eigen::Matrix3d P_;
  Pose2 X_OR_previous_;
  bool has_previous_ = false;
};

// The registration: kind "dead_reckoning" in the program's registry, built
// from its entry of slam.filters. A static object of an object file that is
// linked into the program (examples/CMakeLists.txt) registers it at start-up.
const slam::FilterRegistration kRegistration(
    "dead_reckoning",
    [](const slam::FilterSettings& settings, const Pose2& X_WR0, const Pose2& /*X_RS*/,
       Rng /*rng*/) { return std::make_unique<DeadReckoningFilter>(settings, X_WR0); });

}  // namespace
}  // namespace mjslam::examples
