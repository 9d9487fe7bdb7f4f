// Differential-drive kinematics of the Pioneer and of its point h (pure code).

#include <cmath>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/rng.h"
#include "sim/diff_drive.h"

namespace mjslam::sim {
namespace {

TEST(DiffDriveTest, WheelSpeedsFromTwist) {
  const RobotParams robot;
  const double r = robot.wheel_radius_m;
  const double half_track = 0.5 * robot.axle_track_m;
  const WheelSpeeds straight = WheelSpeedsFromTwist({0.5, 0.0}, robot);
  EXPECT_DOUBLE_EQ(straight.left_radps, 0.5 / r);
  EXPECT_DOUBLE_EQ(straight.right_radps, 0.5 / r);
  const WheelSpeeds spin = WheelSpeedsFromTwist({0.0, 1.0}, robot);
  EXPECT_DOUBLE_EQ(spin.left_radps, -half_track / r);
  EXPECT_DOUBLE_EQ(spin.right_radps, half_track / r);
  const WheelSpeeds arc = WheelSpeedsFromTwist({0.4, -0.7}, robot);
  EXPECT_DOUBLE_EQ(arc.left_radps, (0.4 + 0.7 * half_track) / r);
  EXPECT_DOUBLE_EQ(arc.right_radps, (0.4 - 0.7 * half_track) / r);
}

TEST(DiffDriveTest, TwistFromWheelSpeedsInvertsWheelSpeedsFromTwist) {
  const RobotParams robot;
  Rng rng(7);
  for (int i = 0; i < 100; ++i) {
    const Twist2 command{rng.Gaussian(0, 1), rng.Gaussian(0, 2)};
    const Twist2 back = TwistFromWheelSpeeds(WheelSpeedsFromTwist(command, robot), robot);
    EXPECT_NEAR(back.v_mps, command.v_mps, 1e-12);
    EXPECT_NEAR(back.w_radps, command.w_radps, 1e-12);
  }
}

TEST(DiffDriveTest, CommandsWithinLimitsAreUnchanged) {
  const RobotParams robot;
  for (const Twist2 command : {Twist2{0.0, 0.0}, Twist2{0.5, 0.3}, Twist2{-0.8, -1.0},
                               Twist2{0.0, 2.0}}) {
    const Twist2 applied = SaturateTwist(command, robot);
    EXPECT_EQ(applied.v_mps, command.v_mps);
    EXPECT_EQ(applied.w_radps, command.w_radps);
  }
}

TEST(DiffDriveTest, SaturationKeepsCurvatureAndRespectsEveryLimit) {
  // Seed 11: 2000 commands up to several times the limits.
  const RobotParams robot;
  Rng rng(11);
  for (int i = 0; i < 2000; ++i) {
    const Twist2 command{rng.Gaussian(0.0, 2.0), rng.Gaussian(0.0, 8.0)};
    const Twist2 applied = SaturateTwist(command, robot);
    // One common factor in (0, 1]: same direction, same curvature.
    const double scale = command.v_mps != 0.0 ? applied.v_mps / command.v_mps
                                              : applied.w_radps / command.w_radps;
    ASSERT_GT(scale, 0.0);
    ASSERT_LE(scale, 1.0);
    EXPECT_NEAR(applied.w_radps, scale * command.w_radps, 1e-12);
    // Every limit holds, and the tightest one is reached (no needless slowing).
    const WheelSpeeds wheels = WheelSpeedsFromTwist(applied, robot);
    const double eps = 1e-9;
    EXPECT_LE(std::abs(applied.v_mps), robot.max_linear_speed_mps + eps);
    EXPECT_LE(std::abs(applied.w_radps), robot.max_angular_speed_radps + eps);
    EXPECT_LE(std::abs(wheels.left_radps), robot.max_wheel_speed_radps + eps);
    EXPECT_LE(std::abs(wheels.right_radps), robot.max_wheel_speed_radps + eps);
    if (scale < 1.0) {
      const bool at_limit =
          std::abs(std::abs(applied.v_mps) - robot.max_linear_speed_mps) < 1e-9 ||
          std::abs(std::abs(applied.w_radps) - robot.max_angular_speed_radps) < 1e-9 ||
          std::abs(std::abs(wheels.left_radps) - robot.max_wheel_speed_radps) < 1e-9 ||
          std::abs(std::abs(wheels.right_radps) - robot.max_wheel_speed_radps) < 1e-9;
      EXPECT_TRUE(at_limit) << "command " << command.v_mps << ", " << command.w_radps;
    }
  }
}

TEST(DiffDriveTest, FastArcIsLimitedByTheOuterWheel) {
  // 1.2 m/s with a turn: the outer wheel would exceed its top speed, so both
  // v and w shrink by the same factor, below their own limits.
  const RobotParams robot;
  const Twist2 applied = SaturateTwist({1.2, 1.0}, robot);
  const WheelSpeeds wheels = WheelSpeedsFromTwist(applied, robot);
  EXPECT_NEAR(wheels.right_radps, robot.max_wheel_speed_radps, 1e-9);
  EXPECT_LT(applied.v_mps, 1.2);
  EXPECT_NEAR(applied.w_radps / applied.v_mps, 1.0 / 1.2, 1e-12);
}

// Eq. (6) of the paper integrated with small Euler steps.
Pose2 IntegrateEq6(Pose2 X_WR, const Twist2& command, double duration_s, double a_m) {
  const int steps = 200000;
  const double dt = duration_s / steps;
  double x = X_WR.x;
  double y = X_WR.y;
  double th = X_WR.theta;
  for (int i = 0; i < steps; ++i) {
    const double u = command.v_mps;
    const double w = command.w_radps;
    x += dt * (u * std::cos(th) - a_m * w * std::sin(th));
    y += dt * (u * std::sin(th) + a_m * w * std::cos(th));
    th += dt * w;
  }
  return Pose2(x, y, th);
}

TEST(DiffDriveTest, MoveControlPointIsTheExactSolutionOfEq6) {
  const double a = 0.2;
  const Pose2 start(1.0, -0.5, 0.4);
  for (const Twist2 command : {Twist2{0.5, 0.0}, Twist2{0.0, 1.2}, Twist2{0.4, -0.9},
                               Twist2{-0.3, 0.5}}) {
    const Pose2 exact = MoveControlPoint(start, command, 2.0, a);
    const Pose2 numeric = IntegrateEq6(start, command, 2.0, a);
    EXPECT_NEAR(exact.x, numeric.x, 1e-4) << command.v_mps << " " << command.w_radps;
    EXPECT_NEAR(exact.y, numeric.y, 1e-4);
    EXPECT_NEAR(WrapAngle(exact.theta - numeric.theta), 0.0, 1e-9);
  }
}

TEST(DiffDriveTest, TurningInPlaceMovesPointHOnACircleAroundTheAxle) {
  const double a = 0.2;
  const Pose2 start(0.0, 0.0, 0.0);
  const Pose2 X_WA = start * Pose2(-a, 0.0, 0.0);
  const Pose2 end = MoveControlPoint(start, {0.0, 1.0}, kPi / 2, a);
  EXPECT_NEAR(end.x, X_WA.x, 1e-12);
  EXPECT_NEAR(end.y, X_WA.y + a, 1e-12);
  EXPECT_NEAR(end.theta, kPi / 2, 1e-12);
}

}  // namespace
}  // namespace mjslam::sim
