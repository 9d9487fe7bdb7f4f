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
  const double sigma_v = params.command_noise.v_noise_std_mps +
                         params.command_noise.v_noise_fraction * 0.5;
  const double sigma_first = sigma_v + params.command_noise.change_noise_fraction * 0.5;
  EXPECT_NEAR(filter.pose_covariance()(1, 1),
              0.01 * (sigma_first * sigma_first + 9 * sigma_v * sigma_v), 1e-12);
  EXPECT_GT(filter.pose_covariance()(0, 0), 0.0);
}

// The settle term (command_noise.settle_noise_fraction) widens the step
// after a change of the command by its fraction of that change, and no other:
// the command steps from rest to 0.5 m/s at the first record and is then held.
TEST(EkfSlamTest, SettleNoiseWidensTheStepAfterAChange) {
  EkfParams params;
  params.control_point_offset_m = 0.2;
  params.command_noise.settle_noise_fraction = 0.3;
  EkfSlam filter(params, CorrectionMode::kClassical, Pose2(1.0, 2.0, kPi / 2.0), Pose2());
  SensorRecord record;
  record.dt_s = 0.1;
  record.command = Twist2{0.5, 0.0};
  for (int i = 0; i < 10; ++i) filter.Step(record, nullptr);
  const double sigma_v = params.command_noise.v_noise_std_mps +
                         params.command_noise.v_noise_fraction * 0.5;
  const double sigma_first = sigma_v + params.command_noise.change_noise_fraction * 0.5;
  const double sigma_second = sigma_v + 0.3 * 0.5;
  EXPECT_NEAR(filter.pose_covariance()(1, 1),
              0.01 * (sigma_first * sigma_first + sigma_second * sigma_second +
                      8 * sigma_v * sigma_v),
              1e-12);
}

// Departure 29: a change of the command beyond the calibrated range widens
// both components by the relative excess of this change and the one before;
// within the range nothing changes.
TEST(CommandInputTest, ChangeBeyondTheCalibratedRangeWidensBothComponents) {
  CommandNoiseParams noise;
  noise.v_noise_std_mps = 0.001;
  noise.v_noise_fraction = 0.0;
  noise.w_noise_std_radps = 0.002;
  noise.w_noise_fraction = 0.0;
  noise.change_noise_fraction = 0.0;
  noise.calibrated_change_v_mps = 0.1;
  noise.calibrated_change_w_radps = 0.4;
  noise.beyond_change_noise_fraction = 0.5;
  auto sigmas = [&](const Twist2& command, const Twist2& previous,
                    const Twist2& change) -> Eigen::Vector2d {
    const MotionInput input = CommandInput(command, 0.1, noise, previous, 1.0, 1.0, nullptr,
                                           change);
    return Eigen::Vector2d(std::sqrt(input.covariance(0, 0)), std::sqrt(input.covariance(1, 1))) /
           0.1;
  };
  // Within the range (changes of 0.1 m/s and -0.4 rad/s): the floors alone.
  const Eigen::Vector2d within = sigmas({0.3, -0.4}, {0.2, 0.0}, {0.1, 0.0});
  EXPECT_NEAR(within.x(), 0.001, 1e-15);
  EXPECT_NEAR(within.y(), 0.002, 1e-15);
  // A turn-rate change of 1.2 rad/s, twice beyond 0.4: x = 2, and the speed
  // widens too (f c_v x = 0.5 0.1 2, f c_w x = 0.5 0.4 2).
  const Eigen::Vector2d turn = sigmas({0.3, 1.2}, {0.3, 0.0}, {});
  EXPECT_NEAR(turn.x(), 0.001 + 0.1, 1e-12);
  EXPECT_NEAR(turn.y(), 0.002 + 0.4, 1e-12);
  // The change one record earlier counts too: 0.25 m/s, 1.5 times beyond.
  const Eigen::Vector2d after = sigmas({0.3, 0.0}, {0.3, 0.0}, {-0.25, 0.0});
  EXPECT_NEAR(after.x(), 0.001 + 0.5 * 0.1 * 1.5, 1e-12);
  EXPECT_NEAR(after.y(), 0.002 + 0.5 * 0.4 * 1.5, 1e-12);
  // Off with the fraction 0, whatever the range.
  noise.beyond_change_noise_fraction = 0.0;
  EXPECT_NEAR(sigmas({0.3, 1.2}, {0.3, 0.0}, {}).y(), 0.002, 1e-15);
}

TEST(CommandInputTest, BeyondChangeNeedsItsRange) {
  CommandNoiseParams noise;
  noise.beyond_change_noise_fraction = 0.1;
  noise.calibrated_change_w_radps = 0.4;
  const std::vector<ParamProblem> problems = noise.Validate();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].key, "calibrated_change_v_mps");
  noise.calibrated_change_v_mps = -0.1;
  EXPECT_FALSE(noise.Validate().empty());
  noise.calibrated_change_v_mps = 0.1;
  EXPECT_TRUE(noise.Validate().empty());
}

// The sideways slip by regime (lateral_slip_std_m_per_rad_per_mps,
// lateral_slip_std_m_per_radps_change): with every other noise off, the
// position's variance is the slips' alone, added across the heading.
EkfParams SlipOnlyParams() {
  EkfParams params;
  params.command_noise = CommandNoiseParams{};
  params.command_noise.v_noise_std_mps = 1e-12;  // one of the floors must be > 0
  params.command_noise.v_noise_fraction = 0.0;
  params.command_noise.w_noise_std_radps = 0.0;
  params.command_noise.w_noise_fraction = 0.0;
  params.command_noise.change_noise_fraction = 0.0;
  params.command_lag_s = 0.0;
  params.lateral_skid_s = 0.0;
  params.lateral_slip_std_m_per_rad = 0.001;
  return params;
}

// Steps `filter` through `commands`, 0.1 s each, without scans.
void StepThrough(EkfSlam* filter, const std::vector<Twist2>& commands) {
  SensorRecord record;
  record.dt_s = 0.1;
  for (const Twist2& command : commands) {
    record.command = command;
    filter->Step(record, nullptr);
  }
}

double PositionVarianceAfter(const EkfParams& params, const std::vector<Twist2>& commands) {
  EkfSlam filter(params, CorrectionMode::kClassical, Pose2(1.0, 2.0, 0.3), Pose2());
  StepThrough(&filter, commands);
  return filter.pose_covariance().topLeftCorner<2, 2>().trace();
}

TEST(EkfSlamTest, SlipPerRadianGrowsWithTheSpeed) {
  EkfParams params = SlipOnlyParams();
  params.lateral_slip_std_m_per_rad_per_mps = 0.01;
  // On the spot: 0.001 m/rad of the 0.05 rad turned; at 0.5 m/s:
  // hypot(0.001, 0.01 * 0.5) m/rad.
  EXPECT_NEAR(PositionVarianceAfter(params, {{0.0, 0.5}}), std::pow(0.001 * 0.05, 2), 1e-18);
  EXPECT_NEAR(PositionVarianceAfter(params, {{0.5, 0.5}}),
              std::pow(std::hypot(0.001, 0.005) * 0.05, 2), 1e-18);
  params.lateral_slip_std_m_per_rad_per_mps = 0.0;
  EXPECT_NEAR(PositionVarianceAfter(params, {{0.5, 0.5}}), std::pow(0.001 * 0.05, 2), 1e-18);
}

TEST(EkfSlamTest, SlipAtAChangeOfTheTurnRate) {
  EkfParams params = SlipOnlyParams();
  params.lateral_slip_std_m_per_rad = 0.0;
  params.lateral_slip_std_m_per_radps_change = 0.001;
  // Turning from rest at 0.5 rad/s, held, stopped: two changes of 0.5 rad/s,
  // 0.5 mm each; the held step adds nothing, nor a change of the speed.
  EXPECT_NEAR(PositionVarianceAfter(params, {{0.0, 0.5}, {0.0, 0.5}, {0.0, 0.0}}),
              2.0 * std::pow(0.001 * 0.5, 2), 1e-18);
  EXPECT_NEAR(PositionVarianceAfter(params, {{0.5, 0.0}, {0.0, 0.0}}), 0.0, 1e-18);
  // With odometry the command's change is not the robot's: no slip from it.
  params.input = "odometry";
  params.odometry_noise = OdometryNoiseParams{0.0, 0.0, 0.0, 0.0, 0.0};
  EXPECT_NEAR(PositionVarianceAfter(params, {{0.0, 0.5}, {0.0, 0.0}}), 0.0, 1e-18);
}

Pose2 PoseAfter(const EkfParams& params, const std::vector<Twist2>& commands) {
  EkfSlam filter(params, CorrectionMode::kClassical, Pose2(1.0, 2.0, 0.3), Pose2());
  StepThrough(&filter, commands);
  return filter.X_WR();
}

TEST(EkfSlamTest, TurnOnTheSpotAboutAPointBesideTheAxle) {
  EkfParams params = SlipOnlyParams();
  params.lateral_slip_std_m_per_rad = 0.0;
  EkfParams offset = params;
  offset.turn_centre_offset_m_per_radps = 0.001;
  const auto left = [](double th) { return Eigen::Vector2d(-std::sin(th), std::cos(th)); };
  // On the spot from rest at 0.5 rad/s, held, stopped (0.05 rad a step from
  // heading 0.3; the axle 0.5 mm left of the point it turns about while
  // w = 0.5): each step moves the axle by c n(th') - c_prev n(th), here
  // 0.5 mm left of heading 0.35, then around the point from 0.35 to 0.4,
  // then back by 0.5 mm from the left of heading 0.4.
  const std::vector<Twist2> spot = {{0.0, 0.5}, {0.0, 0.5}, {0.0, 0.0}};
  const Pose2 plain = PoseAfter(params, spot);
  const Pose2 moved = PoseAfter(offset, spot);
  const Eigen::Vector2d expected =
      0.0005 * left(0.35) + 0.0005 * (left(0.4) - left(0.35)) - 0.0005 * left(0.4);
  EXPECT_NEAR(moved.x - plain.x, expected.x(), 1e-15);
  EXPECT_NEAR(moved.y - plain.y, expected.y(), 1e-15);
  EXPECT_EQ(moved.theta, plain.theta);
  // Held for 20 steps of 0.05 rad: the axle circles the point, ending
  // 0.5 mm left of heading 1.3 rather than of 0.35 (a backward creep).
  std::vector<Twist2> held(21, Twist2{0.0, 0.5});
  const Pose2 circled = PoseAfter(offset, held);
  const Pose2 circled_plain = PoseAfter(params, held);
  const Eigen::Vector2d expected_circled = 0.0005 * left(0.3 + 21 * 0.05);
  EXPECT_NEAR(circled.x - circled_plain.x, expected_circled.x(), 1e-15);
  EXPECT_NEAR(circled.y - circled_plain.y, expected_circled.y(), 1e-15);
  // Not while driving, nor in the step that stops or starts the driving.
  for (const std::vector<Twist2>& driving :
       {std::vector<Twist2>{{0.5, 0.5}, {0.5, 0.0}}, std::vector<Twist2>{{0.5, 0.0}, {0.0, 0.5}},
        std::vector<Twist2>{{0.0, 0.5}, {0.5, 0.0}}}) {
    const Pose2 a = PoseAfter(offset, driving);
    const Pose2 b = PoseAfter(params, driving);
    const double first_shift = driving[0].v_mps == 0.0 ? 0.0005 : 0.0;  // from rest, on the spot
    EXPECT_NEAR(std::hypot(a.x - b.x, a.y - b.y), first_shift, 1e-15);
  }
  // With odometry the command is not the robot's turn rate: no offset.
  params.input = offset.input = "odometry";
  params.odometry_noise = offset.odometry_noise = OdometryNoiseParams{0.0, 0.0, 0.0, 0.0, 0.0};
  const Pose2 a = PoseAfter(offset, spot);
  const Pose2 b = PoseAfter(params, spot);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
}

TEST(EkfSlamTest, PredictsFromOdometry) {
  // Odometry generated with Eq. (6)'s own kinematics, (d, a dth, dth) per
  // record in the previous R frame: without skid, the filter must reproduce
  // it exactly; with skid, it must add c d dth / dt outward in every step.
  for (const double skid_s : {0.0, 0.01}) {
    EkfParams params;
    params.input = "odometry";
    params.lateral_skid_s = skid_s;
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
  params.input = "odometry";
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
