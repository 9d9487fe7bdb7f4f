// Wheel odometry: encoder quantisation, exact arc integration, the frame of
// the point h, and the seeded error model (statistical tests state their
// seeds and bounds).

#include <cmath>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/rng.h"
#include "sim/wheel_odometry.h"

namespace mjslam::sim {
namespace {

OdometryParams NoiselessOdometry(int ticks = 76600) {
  OdometryParams odometry;
  odometry.ticks_per_wheel_revolution = ticks;
  odometry.slip_std_fraction = 0.0;
  odometry.wheel_radius_error_std_fraction = 0.0;
  return odometry;
}

TEST(WheelOdometryTest, FirstUpdateDefinesTheOdometryFrame) {
  WheelOdometry odometry(RobotParams{}, NoiselessOdometry(), Rng(1));
  const Pose2 X_OR = odometry.Update({12.3, -4.5});
  EXPECT_EQ(X_OR.x, 0.0);
  EXPECT_EQ(X_OR.y, 0.0);
  EXPECT_EQ(X_OR.theta, 0.0);
}

TEST(WheelOdometryTest, AnglesAreQuantisedToWholeEncoderCounts) {
  // A coarse 100-count encoder: 0.0628 rad per count.
  const RobotParams robot;
  const double count = 2.0 * kPi / 100.0;
  WheelOdometry odometry(robot, NoiselessOdometry(100), Rng(1));
  odometry.Update({0.1 * count, 0.1 * count});
  EXPECT_EQ(odometry.counts()[0], 0);
  // Less than a count further: no motion.
  EXPECT_EQ(odometry.Update({0.8 * count, 0.8 * count}).x, 0.0);
  // Across the next count boundary: exactly one count of travel.
  const Pose2 moved = odometry.Update({1.05 * count, 1.05 * count});
  EXPECT_EQ(odometry.counts()[0], 1);
  EXPECT_NEAR(moved.x, robot.wheel_radius_m * count, 1e-12);
  // Negative angles count down (floor, like a counter).
  odometry.Update({-0.5 * count, -0.5 * count});
  EXPECT_EQ(odometry.counts()[1], -1);
}

TEST(WheelOdometryTest, StraightLine) {
  const RobotParams robot;
  WheelOdometry odometry(robot, NoiselessOdometry(), Rng(1));
  odometry.Update({0.0, 0.0});
  const double angle = 5.0 / robot.wheel_radius_m;  // 5 m
  Pose2 X_OR;
  for (int i = 1; i <= 50; ++i) X_OR = odometry.Update({angle * i / 50, angle * i / 50});
  const double count_m = robot.wheel_radius_m * 2.0 * kPi / 76600;
  EXPECT_NEAR(X_OR.x, 5.0, count_m);
  EXPECT_EQ(X_OR.y, 0.0);
  EXPECT_EQ(X_OR.theta, 0.0);
}

TEST(WheelOdometryTest, TurnInPlaceSwingsPointHAroundTheAxle) {
  const RobotParams robot;
  const double a = robot.control_point_offset_m;
  WheelOdometry odometry(robot, NoiselessOdometry(), Rng(1));
  odometry.Update({0.0, 0.0});
  // Wheels roll pi/2 * L/2 in opposite directions: a quarter turn left.
  const double angle = 0.5 * kPi * 0.5 * robot.axle_track_m / robot.wheel_radius_m;
  Pose2 X_OR;
  for (int i = 1; i <= 20; ++i) X_OR = odometry.Update({-angle * i / 20, angle * i / 20});
  EXPECT_NEAR(X_OR.theta, kPi / 2, 1e-4);
  // The axle stays at (-a, 0) in O; h is a ahead of it along the new heading.
  EXPECT_NEAR(X_OR.x, -a, 1e-4);
  EXPECT_NEAR(X_OR.y, a, 1e-4);
}

TEST(WheelOdometryTest, ArcIntegrationDoesNotDependOnTheUpdateRate) {
  // Constant wheel speeds: the axle moves on an arc, integrated exactly.
  const RobotParams robot;
  const std::array<double, 2> end{30.0, 45.0};
  std::vector<Pose2> results;
  for (const int updates : {1, 7, 1000}) {
    WheelOdometry odometry(robot, NoiselessOdometry(1 << 30), Rng(1));
    odometry.Update({0.0, 0.0});
    Pose2 X_OR;
    for (int i = 1; i <= updates; ++i) {
      X_OR = odometry.Update({end[0] * i / updates, end[1] * i / updates});
    }
    results.push_back(X_OR);
  }
  for (const Pose2& pose : results) {
    EXPECT_NEAR(pose.x, results[0].x, 1e-6);
    EXPECT_NEAR(pose.y, results[0].y, 1e-6);
    EXPECT_NEAR(WrapAngle(pose.theta - results[0].theta), 0.0, 1e-8);
  }
}

// Drives 1 m straight in `updates` steps with seed `seed`; returns X_OR.
Pose2 NoisyMetre(const OdometryParams& params, int updates, std::uint64_t seed) {
  const RobotParams robot;
  WheelOdometry odometry(robot, params, Rng(seed));
  odometry.Update({0.0, 0.0});
  const double angle = 1.0 / robot.wheel_radius_m;
  Pose2 X_OR;
  for (int i = 1; i <= updates; ++i) {
    X_OR = odometry.Update({angle * i / updates, angle * i / updates});
  }
  return X_OR;
}

TEST(WheelOdometryTest, SlipNoiseGrowsWithDistanceNotWithUpdateRate) {
  // Seeds 1..800 per rate. Each wheel's error after 1 m has std 0.01 m, so the
  // heading error has std sqrt(2) * 0.01 / L; standard error of a std from
  // 800 samples is 2.5 %, the bound 12 %.
  const RobotParams robot;
  OdometryParams params = NoiselessOdometry();
  params.slip_std_fraction = 0.01;
  const double expected_heading_std = std::sqrt(2.0) * 0.01 / robot.axle_track_m;
  for (const int updates : {5, 200}) {
    double sum_sq = 0.0;
    const int runs = 800;
    for (int seed = 1; seed <= runs; ++seed) {
      const double heading = NoisyMetre(params, updates, seed).theta;
      sum_sq += heading * heading;
    }
    const double heading_std = std::sqrt(sum_sq / runs);
    std::cout << updates << " updates: heading std " << heading_std << " rad (expected "
              << expected_heading_std << ")\n";
    EXPECT_NEAR(heading_std, expected_heading_std, 0.12 * expected_heading_std);
  }
}

TEST(WheelOdometryTest, SystematicRadiusErrorIsFixedPerRun) {
  OdometryParams params = NoiselessOdometry(1 << 30);  // quantisation negligible
  params.wheel_radius_error_std_fraction = 0.01;
  // Same seed: the same error in every run; and it bends a straight line.
  const Pose2 first = NoisyMetre(params, 10, 42);
  const Pose2 again = NoisyMetre(params, 10, 42);
  EXPECT_EQ(first.theta, again.theta);
  EXPECT_NE(first.theta, 0.0);
  // Twice as far, twice the heading error (a constant error, not a random walk).
  const RobotParams robot;
  WheelOdometry odometry(robot, params, Rng(42));
  odometry.Update({0.0, 0.0});
  const double angle = 2.0 / robot.wheel_radius_m;
  const Pose2 two_metres = odometry.Update({angle, angle});
  EXPECT_NEAR(two_metres.theta, 2.0 * first.theta, 1e-4 * std::abs(first.theta) + 1e-9);
}

TEST(WheelOdometryTest, SameSeedSameOdometry) {
  OdometryParams params;
  params.slip_std_fraction = 0.02;
  const Pose2 a = NoisyMetre(params, 30, 9);
  const Pose2 b = NoisyMetre(params, 30, 9);
  const Pose2 c = NoisyMetre(params, 30, 10);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.theta, b.theta);
  EXPECT_NE(a.theta, c.theta);
}

TEST(WheelOdometryTest, InvalidParamsThrow) {
  OdometryParams params;
  params.ticks_per_wheel_revolution = 0;
  EXPECT_THROW(WheelOdometry(RobotParams{}, params, Rng(1)), ParamError);
}

}  // namespace
}  // namespace mjslam::sim
