// The command noise of a robot whose wheels vary each on its own
// (CommandNoiseParams::turn_v_noise_m_per_rad, speed_w_noise_rad_per_m;
// docs/method.md, departure 26): turning widens the speed's noise, driving
// the turn rate's.

#include "slam/ekf_slam.h"
#include "slam/motion_model.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "slam/slam_params.h"

namespace mjslam::slam {
namespace {

// Every other term of the command noise off.
CommandNoiseParams WheelNoiseOnly(double turn_v, double speed_w) {
  CommandNoiseParams noise;
  noise.v_noise_std_mps = 0.0;
  noise.v_noise_fraction = 0.0;
  noise.w_noise_std_radps = 0.0;
  noise.w_noise_fraction = 0.0;
  noise.change_noise_fraction = 0.0;
  noise.turn_v_noise_m_per_rad = turn_v;
  noise.speed_w_noise_rad_per_m = speed_w;
  return noise;
}

TEST(WheelNoiseTest, TurningWidensTheSpeedAndDrivingTheTurnRate) {
  const CommandNoiseParams noise = WheelNoiseOnly(0.002, 0.04);
  const Twist2 spin{0.0, -0.8};
  const MotionInput on_the_spot = CommandInput(spin, 0.1, noise, spin);
  EXPECT_NEAR(std::sqrt(on_the_spot.covariance(0, 0)), 0.1 * 0.002 * 0.8, 1e-15);
  EXPECT_EQ(on_the_spot.covariance(1, 1), 0.0);
  const Twist2 straight{0.5, 0.0};
  const MotionInput driving = CommandInput(straight, 0.1, noise, straight);
  EXPECT_EQ(driving.covariance(0, 0), 0.0);
  EXPECT_NEAR(std::sqrt(driving.covariance(1, 1)), 0.1 * 0.04 * 0.5, 1e-15);
  // The terms follow the speeds the wheels move at (the lag), not the
  // command: the robot still turning after the command to stop.
  const Twist2 stop{0.0, 0.0};
  const Twist2 still_turning{0.0, -0.4};
  const MotionInput stopping = CommandInput(stop, 0.1, noise, stop, 1.0, 1.0, &still_turning);
  EXPECT_NEAR(std::sqrt(stopping.covariance(0, 0)), 0.1 * 0.002 * 0.4, 1e-15);
}

// A filter turning on the spot becomes uncertain along its heading, which
// without the term it stays certain of (the speed's floor aside).
TEST(WheelNoiseTest, TurningOnTheSpotMakesThePositionUncertain) {
  EkfParams params;
  params.control_point_offset_m = 0.2;
  params.command_noise = WheelNoiseOnly(0.002, 0.0);
  params.command_noise.v_noise_std_mps = 1e-12;  // one of the floors must be > 0
  params.lateral_slip_std_m_per_rad = 0.0;
  params.lateral_skid_s = 0.0;
  auto position_variance = [&](const EkfParams& p) {
    EkfSlam filter(p, CorrectionMode::kClassical, Pose2(0.0, 0.0, 0.0), Pose2());
    SensorRecord record;
    record.dt_s = 0.1;
    record.command = Twist2{0.0, 0.5};
    for (int i = 0; i < 20; ++i) filter.Step(record, nullptr);
    return filter.pose_covariance().topLeftCorner<2, 2>().trace();
  };
  // 20 steps of (0.1 * 0.002 * 0.5)^2 each (the direction turns, the trace
  // does not), times the chord's sinc(0.025)^2 = 1 - 2.1e-4.
  EXPECT_NEAR(position_variance(params), 20 * std::pow(0.1 * 0.002 * 0.5, 2), 1e-4 * 2e-7 * 3);
  params.command_noise.turn_v_noise_m_per_rad = 0.0;
  EXPECT_LT(position_variance(params), 1e-20);
}

TEST(WheelNoiseTest, ParamsNameANegativeTerm) {
  CommandNoiseParams noise;
  noise.turn_v_noise_m_per_rad = -1e-3;
  noise.speed_w_noise_rad_per_m = NAN;
  std::string keys;
  for (const ParamProblem& problem : noise.Validate()) keys += problem.key + " ";
  EXPECT_EQ(keys, "turn_v_noise_m_per_rad speed_w_noise_rad_per_m ");
}

}  // namespace
}  // namespace mjslam::slam
