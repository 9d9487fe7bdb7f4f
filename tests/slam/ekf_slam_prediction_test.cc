// EkfSlam's prediction without scans: from commands (the command noise, the
// settle term, the sideways slip by regime, the turn on the spot about a
// point beside the axle) and from odometry (skid, arbitrary odometry frame).

#include "slam/ekf_slam.h"
#include "slam/motion_model.h"

#include <cmath>
#include <vector>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "common/angles.h"
#include "slam/slam_params.h"

namespace mjslam::slam {
namespace {

TEST(EkfSlamTest, PredictsFromCommands) {
  EkfParams params;
  params.control_point_offset_m = 0.2;
  EkfSlam filter(params, CorrectionMode::kClassical, Pose2(1.0, 2.0, kPi / 2.0), Pose2());
  SensorRecord record;
  record.dt_s = 0.1;
  record.command = Twist2{0.5, 0.0};
  for (int i = 0; i < 10; ++i) {
    const StepReport report = filter.Step(record, nullptr);
    EXPECT_EQ(report.num_observed, 0);
    EXPECT_EQ(report.num_updated, 0);
  }
  EXPECT_NEAR(filter.X_WR().x, 1.0, 1e-12);
  EXPECT_NEAR(filter.X_WR().y, 2.5, 1e-12);
  // The covariance grew from zero along the motion: sigma_v dt per step, the
  // first step also half the command's step from rest.
  const CommandNoiseParams& noise = std::get<CommandProcessModel>(params.process_model).noise;
  const double sigma_v = noise.v_std_mps + noise.v_fraction * 0.5;
  const double sigma_first = sigma_v + noise.change_fraction * 0.5;
  EXPECT_NEAR(filter.pose_covariance()(1, 1),
              0.01 * (sigma_first * sigma_first + 9 * sigma_v * sigma_v), 1e-12);
  EXPECT_GT(filter.pose_covariance()(0, 0), 0.0);
}

TEST(EkfSlamTest, PredictsFromOdometry) {
  // Odometry generated with Eq. (6)'s own kinematics, (d, a dth, dth) per
  // record in the previous R frame: without skid, the filter must reproduce
  // it exactly; with skid, it must add c d dth / dt outward in every step.
  for (const double skid_s : {0.0, 0.01}) {
    EkfParams params;
    OdometryProcessModel odometry;
    odometry.lateral.skid_s = skid_s;
    params.process_model = odometry;
    params.control_point_offset_m = 0.15;
    const Pose2 X_WR0(3.0, -1.0, 0.4);
    EkfSlam filter(params, CorrectionMode::kSelective, X_WR0, Pose2());
    Pose2 X_OR;
    Pose2 X_true = X_WR0;  // R in W, moved as the filter's model moves it
    SensorRecord record;
    for (int i = 0; i < 50; ++i) {
      const double d = 0.05;
      const double dth = 0.04 * std::sin(0.1 * i);
      if (i > 0) {
        const Eigen::Vector3d step = PredictPose(Eigen::Vector3d::Zero(), Eigen::Vector2d(d, dth),
                                                 params.control_point_offset_m);
        X_OR = X_OR * Pose2(step.x(), step.y(), step.z());
      }
      record.dt_s = i == 0 ? 0.0 : 0.1;
      record.X_OR = X_OR;
      record.command = Twist2{100.0, 100.0};  // ignored
      filter.Step(record, nullptr);
      if (i > 0) {
        const Eigen::Vector3d step = PredictPose(Eigen::Vector3d::Zero(), Eigen::Vector2d(d, dth),
                                                 params.control_point_offset_m, nullptr, nullptr,
                                                 skid_s / record.dt_s);
        X_true = X_true * Pose2(step.x(), step.y(), step.z());
      }
    }
    EXPECT_NEAR(filter.X_WR().x, X_true.x, 1e-9) << "skid " << skid_s;
    EXPECT_NEAR(filter.X_WR().y, X_true.y, 1e-9) << "skid " << skid_s;
    EXPECT_NEAR(WrapAngle(filter.X_WR().theta - X_true.theta), 0.0, 1e-9) << "skid " << skid_s;
    // The skid is 0.01 / 0.1 * 0.05 * |dth| <= 0.2 mm a step.
    const double off = (filter.X_WR().translation() - (X_WR0 * X_OR).translation()).norm();
    if (skid_s > 0.0) {
      EXPECT_GT(off, 1e-4);
    } else {
      EXPECT_LT(off, 1e-9);
    }
    EXPECT_GT(filter.pose_covariance().determinant(), 0.0);
  }
}

TEST(EkfSlamTest, OdometryFrameIsArbitrary) {
  // Only increments enter: odometry expressed in another fixed frame (and not
  // starting at the identity) gives the same estimate.
  EkfParams params;
  params.process_model = OdometryProcessModel{};
  const Pose2 X_WR0(1.0, 2.0, -0.3);
  const Pose2 X_QO(-7.0, 4.0, 2.5);  // some other frame Q
  EkfSlam in_O(params, CorrectionMode::kSelective, X_WR0, Pose2());
  EkfSlam in_Q(params, CorrectionMode::kSelective, X_WR0, Pose2());
  Pose2 X_OR;
  for (int i = 0; i < 30; ++i) {
    if (i > 0) X_OR = X_OR * Pose2(0.04, 0.01, 0.03);
    SensorRecord record;
    record.dt_s = i == 0 ? 0.0 : 0.1;
    record.X_OR = X_OR;
    in_O.Step(record, nullptr);
    record.X_OR = X_QO * X_OR;
    in_Q.Step(record, nullptr);
  }
  EXPECT_NEAR(in_O.X_WR().x, in_Q.X_WR().x, 1e-9);
  EXPECT_NEAR(in_O.X_WR().y, in_Q.X_WR().y, 1e-9);
  EXPECT_NEAR(WrapAngle(in_O.X_WR().theta - in_Q.X_WR().theta), 0.0, 1e-9);
  EXPECT_GT(in_O.X_WR().Inverse().translation().norm(), 0.5);  // it did move
}

}  // namespace
}  // namespace mjslam::slam
