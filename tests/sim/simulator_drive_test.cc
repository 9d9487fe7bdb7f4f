// The simulated Pioneer drives like the real one: it settles at its start
// pose, drives straight, turns in place, saturates keeping the curvature,
// follows the kinematics of the point h (the paper's Eq. (6)), and never
// raises a MuJoCo warning at the chosen timestep and gains.

#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/rng.h"
#include "sim/diff_drive.h"
#include "sim/simulator.h"
#include "sim/wheel_odometry.h"
#include "tests/sim/sim_test_util.h"

namespace mjslam::sim {
namespace {

using testing::MujocoTest;
using testing::RobotModelPath;
using testing::WorldXml;
using testing::WriteTempFile;

// A large empty floor: nothing to hit.
std::string EmptyWorld() { return WriteTempFile("empty_world.xml", WorldXml("")); }

class SimulatorDriveTest : public MujocoTest {};

TEST_F(SimulatorDriveTest, SettlesAtTheStartPoseWithoutBouncing) {
  const Pose2 start(1.0, -2.0, DegToRad(30.0));
  Simulator sim(EmptyWorld(), RobotModelPath(), SimParams{}, RobotParams{}, start);
  EXPECT_DOUBLE_EQ(sim.time_s(), 0.0);
  const Pose2 settled = sim.X_WR();
  EXPECT_NEAR(settled.x, start.x, 1e-3);
  EXPECT_NEAR(settled.y, start.y, 1e-3);
  EXPECT_NEAR(WrapAngle(settled.theta - start.theta), 0.0, DegToRad(0.05));
  // At rest, and it stays there.
  sim.Advance(2.0);
  const Pose2 later = sim.X_WR();
  EXPECT_NEAR(later.x, settled.x, 1e-4);
  EXPECT_NEAR(later.y, settled.y, 1e-4);
  EXPECT_NEAR(WrapAngle(later.theta - settled.theta), 0.0, 1e-4);
  EXPECT_NEAR(sim.TrueTwist().v_mps, 0.0, 1e-4);
  EXPECT_NEAR(sim.TrueTwist().w_radps, 0.0, 1e-4);
  EXPECT_EQ(sim.CountRobotWorldContacts(), 0);
}

TEST_F(SimulatorDriveTest, UsesTheWorldStartSiteByDefault) {
  const std::string world = WriteTempFile(
      "start_site_world.xml",
      WorldXml("", "<site name=\"start\" pos=\"2 3 0\" euler=\"0 0 -45\"/>"));
  Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{});
  EXPECT_NEAR(sim.scene().StartPose().x, 2.0, 1e-12);
  EXPECT_NEAR(sim.scene().StartPose().y, 3.0, 1e-12);
  EXPECT_NEAR(sim.scene().StartPose().theta, DegToRad(-45.0), 1e-12);
  EXPECT_NEAR(sim.X_WR().x, 2.0, 1e-3);
  EXPECT_NEAR(sim.X_WR().y, 3.0, 1e-3);
  EXPECT_NEAR(sim.X_WR().theta, DegToRad(-45.0), DegToRad(0.05));
}

TEST_F(SimulatorDriveTest, AdvanceTakesWholeStepsWithoutAccumulatingRoundOff) {
  Simulator sim(EmptyWorld(), RobotModelPath(), SimParams{}, RobotParams{});
  for (int i = 0; i < 10; ++i) sim.Advance(0.1);
  EXPECT_NEAR(sim.time_s(), 1.0, 1e-9);
  // 0.0031 s is 1.55 steps: rounds to 2, and the remainder is carried over
  // (0.0062 s in all is 3.1 steps: one more).
  sim.Advance(0.0031);
  EXPECT_NEAR(sim.time_s(), 1.004, 1e-9);
  sim.Advance(0.0031);
  EXPECT_NEAR(sim.time_s(), 1.006, 1e-9);
  EXPECT_THROW(sim.Advance(-0.1), SimError);
}

// The drive's disturbance scales the set points, not the command reported:
// 2 s at (0.5 m/s, 0.5 rad/s) with factors (1.1, 0.9) against factors 1 ends
// about 10 % farther along the arc with about 10 % less turn (measured with
// TrueTwist at the end), and command() is the command as given.
TEST_F(SimulatorDriveTest, DriveFactorsScaleTheSetPointsNotTheCommand) {
  const auto drive = [&](double v_factor, double w_factor) {
    Simulator sim(EmptyWorld(), RobotModelPath(), SimParams{}, RobotParams{}, Pose2(0, 0, 0));
    sim.SetCommand({0.5, 0.5});
    sim.SetDriveFactors(v_factor, w_factor);
    sim.Advance(2.0);
    EXPECT_DOUBLE_EQ(sim.command().v_mps, 0.5);
    EXPECT_DOUBLE_EQ(sim.command().w_radps, 0.5);
    return sim.TrueTwist();
  };
  const Twist2 exact = drive(1.0, 1.0);
  const Twist2 disturbed = drive(1.1, 0.9);
  EXPECT_NEAR(disturbed.v_mps / exact.v_mps, 1.1, 0.01);
  EXPECT_NEAR(disturbed.w_radps / exact.w_radps, 0.9, 0.01);
}

// Each wheel's own disturbance (SetWheelFactors): on the spot, a right
// wheel faster than the left one moves the robot forward as it turns, which
// the twist's factors never do; driving straight, it turns the robot left.
TEST_F(SimulatorDriveTest, WheelFactorsScaleEachWheelsSetPoint) {
  const auto drive = [&](const Twist2& command, double left, double right) {
    Simulator sim(EmptyWorld(), RobotModelPath(), SimParams{}, RobotParams{}, Pose2(0, 0, 0));
    sim.SetCommand(command);
    sim.SetWheelFactors(left, right);
    sim.Advance(2.0);
    EXPECT_DOUBLE_EQ(sim.command().v_mps, command.v_mps);
    return sim.TrueTwist();
  };
  const RobotParams robot;
  const double rim = 0.5 * 0.6 * robot.axle_track_m;  // each wheel's speed at 0.6 rad/s, m/s
  const Twist2 spin = drive({0.0, 0.6}, 0.9, 1.1);
  EXPECT_NEAR(spin.v_mps, 0.1 * rim, 0.05 * rim);  // (1.1 rim - 0.9 rim) / 2
  EXPECT_NEAR(spin.w_radps, 0.6, 0.02);
  EXPECT_NEAR(drive({0.0, 0.6}, 1.0, 1.0).v_mps, 0.0, 1e-3 * rim);
  const Twist2 straight = drive({0.5, 0.0}, 0.99, 1.01);
  EXPECT_NEAR(straight.w_radps, 0.01 / robot.axle_track_m, 0.1 * 0.01 / robot.axle_track_m);
  EXPECT_NEAR(straight.v_mps, 0.5, 0.01);
}

// The drive's own acceleration limits (sim.command_accel_mps2, _radps2): the
// set points ramp toward the command, so after 0.5 s of a step to 0.4 m/s and
// 1 rad/s at 0.3 m/s^2 and 1.745 rad/s^2 the robot is near 0.15 m/s and 0.87
// rad/s (the ramp's values, less the wheels' lag behind them), and without
// the limits it has reached the command.
TEST_F(SimulatorDriveTest, TheDrivesAccelerationLimitsRampTheSetPoints) {
  const auto after = [&](double accel_mps2, double accel_radps2, double seconds) {
    SimParams params;
    params.command_accel_mps2 = accel_mps2;
    params.command_accel_radps2 = accel_radps2;
    Simulator sim(EmptyWorld(), RobotModelPath(), params, RobotParams{}, Pose2(0, 0, 0));
    sim.SetCommand({0.4, 1.0});
    sim.Advance(seconds);
    EXPECT_DOUBLE_EQ(sim.command().v_mps, 0.4);  // the command as given
    return sim.TrueTwist();
  };
  const Twist2 ramped = after(0.3, 1.745, 0.5);
  EXPECT_LT(ramped.v_mps, 0.15);
  EXPECT_GT(ramped.v_mps, 0.12);
  EXPECT_LT(ramped.w_radps, 0.8725);
  EXPECT_GT(ramped.w_radps, 0.75);
  const Twist2 free = after(0.0, 0.0, 0.5);
  EXPECT_NEAR(free.v_mps, 0.4, 0.01);
  EXPECT_NEAR(free.w_radps, 1.0, 0.03);
  // The ramp ends at the command.
  const Twist2 later = after(0.3, 1.745, 2.5);
  EXPECT_NEAR(later.v_mps, 0.4, 0.01);
  EXPECT_NEAR(later.w_radps, 1.0, 0.03);
}

// Drives straight with `speed` until the point h has covered 5 m; returns the
// heading change (rad) and the lateral offset (m) from the start line.
std::pair<double, double> DriveStraightFiveMetres(double speed_mps) {
  Simulator sim(EmptyWorld(), RobotModelPath(), SimParams{}, RobotParams{}, Pose2(0, 0, 0));
  sim.SetCommand({speed_mps, 0.0});
  while (sim.X_WR().x < 5.0 && sim.time_s() < 60.0) sim.Advance(0.1);
  const Pose2 end = sim.X_WR();
  EXPECT_GE(end.x, 5.0);
  return {end.theta, end.y};
}

TEST_F(SimulatorDriveTest, DrivesStraightFiveMetresWithLessThanOneDegreeOfDrift) {
  for (const double speed : {0.3, 0.7, 1.2}) {
    const auto [heading_change, lateral] = DriveStraightFiveMetres(speed);
    std::cout << "straight 5 m at " << speed << " m/s: heading drift "
              << RadToDeg(heading_change) << " deg, lateral " << lateral << " m\n";
    EXPECT_LT(std::abs(heading_change), DegToRad(1.0)) << "speed " << speed;
    EXPECT_LT(std::abs(lateral), 0.02) << "speed " << speed;
  }
}

TEST_F(SimulatorDriveTest, TurnsInPlaceAboutTheAxleCentre) {
  const RobotParams robot;
  Simulator sim(EmptyWorld(), RobotModelPath(), SimParams{}, robot, Pose2(0, 0, 0));
  const Pose2 X_WA_start = sim.X_WR() * Pose2(-robot.control_point_offset_m, 0, 0);
  const double w = 1.5;
  sim.SetCommand({0.0, w});
  sim.Advance(1.0);  // spin up
  EXPECT_NEAR(sim.TrueTwist().w_radps, w, 0.01 * w);
  EXPECT_NEAR(sim.TrueTwist().v_mps, 0.0, 0.005);
  // A further 2 s: the yaw advances by w * 2 and the axle centre stays put,
  // so the point h moves on a circle of radius a around it.
  const double yaw_before = sim.X_WR().theta;
  sim.Advance(2.0);
  const double yaw_after = sim.X_WR().theta;
  EXPECT_NEAR(WrapAngle(yaw_after - yaw_before - 2.0 * w), 0.0, DegToRad(1.0));
  const Pose2 X_WA = sim.X_WR() * Pose2(-robot.control_point_offset_m, 0, 0);
  const double axle_drift = std::hypot(X_WA.x - X_WA_start.x, X_WA.y - X_WA_start.y);
  std::cout << "turn in place at " << w << " rad/s for 3 s: axle centre moved " << axle_drift
            << " m, yaw rate " << sim.TrueTwist().w_radps << " rad/s\n";
  EXPECT_LT(axle_drift, 0.01);
  const Eigen::Vector2d h_from_axle = sim.X_WR().translation() - X_WA.translation();
  EXPECT_NEAR(h_from_axle.norm(), robot.control_point_offset_m, 1e-6);
}

TEST_F(SimulatorDriveTest, SaturatesKeepingTheCurvatureAndWheelLimits) {
  const RobotParams robot;
  Simulator sim(EmptyWorld(), RobotModelPath(), SimParams{}, robot, Pose2(0, 0, 0));
  const Twist2 wanted{3.0, 2.0};
  const Twist2 applied = sim.SetCommand(wanted);
  EXPECT_NEAR(applied.w_radps / applied.v_mps, wanted.w_radps / wanted.v_mps, 1e-12);
  sim.Advance(1.5);
  for (const double speed : sim.WheelVelocities()) {
    EXPECT_LE(std::abs(speed), robot.max_wheel_speed_radps * 1.001);
  }
  // The driven path has the commanded curvature.
  const Twist2 measured = sim.TrueTwist();
  EXPECT_NEAR(measured.w_radps / measured.v_mps, wanted.w_radps / wanted.v_mps, 0.01);
}

TEST_F(SimulatorDriveTest, PointHFollowsTheUnicycleKinematics) {
  const RobotParams robot;
  Simulator sim(EmptyWorld(), RobotModelPath(), SimParams{}, robot, Pose2(0.5, 0.2, 0.3));
  const Twist2 command{0.4, 0.6};
  sim.SetCommand(command);
  sim.Advance(1.0);  // reach steady state
  const Pose2 before = sim.X_WR();
  sim.Advance(3.0);
  const Pose2 predicted = MoveControlPoint(before, command, 3.0, robot.control_point_offset_m);
  const Pose2 actual = sim.X_WR();
  std::cout << "arc (0.4 m/s, 0.6 rad/s) for 3 s: position error "
            << std::hypot(actual.x - predicted.x, actual.y - predicted.y) << " m, heading error "
            << RadToDeg(WrapAngle(actual.theta - predicted.theta)) << " deg\n";
  EXPECT_NEAR(actual.x, predicted.x, 0.01);
  EXPECT_NEAR(actual.y, predicted.y, 0.01);
  EXPECT_NEAR(WrapAngle(actual.theta - predicted.theta), 0.0, DegToRad(1.0));
}

TEST_F(SimulatorDriveTest, RandomCommandsAtTheLimitsRaiseNoWarning) {
  // Seeded command sequence: 30 s of 10 Hz steps between the extremes.
  Rng rng(20240521);
  Simulator sim(EmptyWorld(), RobotModelPath(), SimParams{}, RobotParams{}, Pose2(0, 0, 0));
  for (int i = 0; i < 300; ++i) {
    sim.SetCommand({rng.Gaussian(0.0, 1.0), rng.Gaussian(0.0, 4.0)});
    ASSERT_NO_THROW(sim.Advance(0.1)) << "seed 20240521, step " << i;
  }
  EXPECT_EQ(sim.CountRobotWorldContacts(), 0);
}

TEST_F(SimulatorDriveTest, NoiselessOdometryFromTheWheelAnglesTracksTheTruePose) {
  // The encoders read the simulated wheels: forward is positive on both, and
  // the only odometry error left is the tyres' creep in the soft contacts.
  const RobotParams robot;
  OdometryParams params;
  params.slip_std_fraction = 0.0;
  Simulator sim(EmptyWorld(), RobotModelPath(), SimParams{}, robot, Pose2(1, 2, 0.5));
  WheelOdometry odometry(robot, params, Rng(1));
  odometry.Update(sim.WheelAngles());
  const Pose2 X_WO = sim.X_WR();
  double driven = 0.0;
  for (int i = 0; i < 200; ++i) {
    sim.SetCommand({0.5, 0.8 * std::sin(0.05 * i)});
    const Pose2 before = sim.X_WR();
    sim.Advance(0.1);
    driven += std::hypot(sim.X_WR().x - before.x, sim.X_WR().y - before.y);
    odometry.Update(sim.WheelAngles());
  }
  const Pose2 X_OR_true = X_WO.Inverse() * sim.X_WR();
  const Pose2 X_OR = odometry.X_OR();
  const double position_error = std::hypot(X_OR.x - X_OR_true.x, X_OR.y - X_OR_true.y);
  std::cout << "odometry after " << driven << " m of S-curves: position error " << position_error
            << " m, heading error " << RadToDeg(WrapAngle(X_OR.theta - X_OR_true.theta))
            << " deg\n";
  EXPECT_LT(position_error, 0.01 * driven);
  EXPECT_NEAR(WrapAngle(X_OR.theta - X_OR_true.theta), 0.0, DegToRad(1.0));
}

TEST_F(SimulatorDriveTest, SameInputsGiveBitIdenticalRuns) {
  const auto run = []() {
    Simulator sim(EmptyWorld(), RobotModelPath(), SimParams{}, RobotParams{}, Pose2(0, 0, 0));
    Rng rng(3);
    for (int i = 0; i < 50; ++i) {
      sim.SetCommand({rng.Gaussian(0.3, 0.3), rng.Gaussian(0.0, 1.0)});
      sim.Advance(0.1);
    }
    return sim.QPos();
  };
  EXPECT_EQ(run(), run());
}

TEST_F(SimulatorDriveTest, DrivingIntoAWallStopsTheRobotWithoutWarnings) {
  // Full speed into a wall, head on and at 30 degrees: the robot stops at the
  // wall, stays on the floor, and the contacts are reported.
  const std::string world = WriteTempFile(
      "crash_world.xml",
      WorldXml("<geom name=\"wall\" type=\"box\" size=\"0.1 3 0.5\" pos=\"2.1 0 0.5\"/>"));
  for (const double yaw : {0.0, DegToRad(30.0)}) {
    Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{}, Pose2(0, 0, yaw));
    sim.SetCommand({1.2, 0.0});
    ASSERT_NO_THROW(sim.Advance(4.0)) << "yaw " << yaw;
    EXPECT_GT(sim.CountRobotWorldContacts(), 0);
    // The chassis front (0.18 m ahead of the axle) is at the wall face (x = 2).
    const Pose2 X_WA = sim.X_WR() * Pose2(-0.2, 0.0, 0.0);
    EXPECT_LT(X_WA.x, 2.0 - 0.17 * std::cos(X_WA.theta));
    sim.SetCommand({-0.3, 0.0});
    ASSERT_NO_THROW(sim.Advance(1.0));
    EXPECT_EQ(sim.CountRobotWorldContacts(), 0);
  }
}

TEST_F(SimulatorDriveTest, AdvanceThrowsWhenTheRobotLeavesTheFloorPlane) {
  // A 15 degree ramp whose top face meets the floor at x = 1 m: the robot
  // climbs it, which breaks the flat-world assumption, and Advance says so.
  const std::string world = WriteTempFile(
      "ramp_world.xml",
      WorldXml("<geom name=\"ramp\" type=\"box\" size=\"2 2 0.5\" "
               "pos=\"3.0614 0 0.0346\" euler=\"0 -15 0\"/>"));
  Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{}, Pose2(0.2, 0, 0));
  sim.SetCommand({0.5, 0.0});
  try {
    for (int i = 0; i < 100; ++i) sim.Advance(0.1);
    FAIL() << "no SimError; robot at x = " << sim.X_WR().x;
  } catch (const SimError& error) {
    EXPECT_NE(std::string(error.what()).find("left the floor"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace mjslam::sim
