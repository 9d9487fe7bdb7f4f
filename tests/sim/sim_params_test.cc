// The sim's Params structs: defaults are valid and consistent, every bad
// value is reported under its key, and Serialize visits every field under its
// documented (flat) key.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "sim/sim_params.h"

namespace mjslam::sim {
namespace {

// Records the keys a Params struct visits.
struct KeyRecorder {
  std::vector<std::string> keys;
  template <typename T>
  void Visit(const NameValue<T>& field) {
    keys.push_back(field.name);
  }
};

template <typename Params>
std::vector<std::string> Keys() {
  Params params;
  KeyRecorder recorder;
  params.Serialize(&recorder);
  return recorder.keys;
}

std::vector<std::string> ProblemKeys(const std::vector<ParamProblem>& problems) {
  std::vector<std::string> keys;
  for (const ParamProblem& problem : problems) keys.push_back(problem.key);
  return keys;
}

TEST(SimParamsTest, DefaultsAreValid) {
  EXPECT_TRUE(SimParams{}.Validate().empty());
  SimParams negative_ramp;
  negative_ramp.command_accel_radps2 = -1.0;
  ASSERT_EQ(negative_ramp.Validate().size(), 1u);
  EXPECT_EQ(negative_ramp.Validate()[0].key, "command_accel_radps2");
  EXPECT_TRUE(RobotParams{}.Validate().empty());
  EXPECT_TRUE(LaserParams{}.Validate().empty());
  EXPECT_TRUE(OdometryParams{}.Validate().empty());
}

TEST(SimParamsTest, RobotDefaultsAreConsistent) {
  // The wheel-speed limit is the linear limit at the wheel radius, and
  // turning in place at full yaw rate stays within it.
  const RobotParams robot;
  EXPECT_NEAR(robot.max_wheel_speed_radps * robot.wheel_radius_m, robot.max_linear_speed_mps, 1e-4);
  EXPECT_LT(robot.max_angular_speed_radps * 0.5 * robot.axle_track_m / robot.wheel_radius_m,
            robot.max_wheel_speed_radps);
}

TEST(SimParamsTest, SerializeVisitsEveryFieldUnderItsKey) {
  EXPECT_EQ(Keys<SimParams>(),
            (std::vector<std::string>{"timestep_s", "settle_time_s", "wheel_speed_kp_nms_per_rad",
                                      "wheel_speed_ki_nm_per_rad",
                                      "drive_disturbance_std_fraction",
                                      "drive_disturbance", "command_accel_mps2",
                                      "command_accel_radps2", "max_world_extent_m"}));
  EXPECT_EQ(Keys<RobotParams>(),
            (std::vector<std::string>{"control_point_offset_m", "wheel_radius_m", "axle_track_m",
                                      "max_wheel_speed_radps", "max_linear_speed_mps",
                                      "max_angular_speed_radps"}));
  // The noise fields are flat: laser.range_noise_std_m on the command line.
  EXPECT_EQ(Keys<LaserParams>(),
            (std::vector<std::string>{"num_beams", "fov_deg", "max_range_m", "rate_hz",
                                      "range_noise_std_m", "range_bias_m", "range_bias_std_m",
                                      "range_scale_fraction", "range_scale_std_fraction",
                                      "angle_jitter_std_deg", "dropout_probability",
                                      "range_noise_std_per_m", "range_resolution_m",
                                      "mixed_pixel_probability", "mixed_pixel_min_step_m",
                                      "beam_divergence_deg", "footprint_rays",
                                      "grazing_dropout_probability",
                                      "grazing_dropout_start_deg"}));
  EXPECT_EQ(Keys<OdometryParams>(),
            (std::vector<std::string>{"ticks_per_wheel_revolution", "slip_std_fraction",
                                      "wheel_radius_error_std_fraction",
                                      "left_wheel_radius_error_fraction",
                                      "right_wheel_radius_error_fraction",
                                      "axle_track_error_std_fraction", "axle_track_error_fraction",
                                      "correlated_slip_std_fraction",
                                      "slip_correlation_distance_m"}));
}

TEST(SimParamsTest, BadValuesAreReportedUnderTheirKeys) {
  SimParams sim;
  sim.timestep_s = 0.05;
  sim.wheel_speed_kp_nms_per_rad = 0.0;
  sim.drive_disturbance_std_fraction = 0.5;
  sim.drive_disturbance = "wheel";
  EXPECT_EQ(ProblemKeys(sim.Validate()),
            (std::vector<std::string>{"timestep_s", "wheel_speed_kp_nms_per_rad",
                                      "drive_disturbance_std_fraction", "drive_disturbance"}));

  RobotParams robot;
  robot.control_point_offset_m = 0.0;
  robot.axle_track_m = -0.3;
  EXPECT_EQ(ProblemKeys(robot.Validate()),
            (std::vector<std::string>{"control_point_offset_m", "axle_track_m"}));

  LaserParams laser;
  laser.num_beams = 1;
  laser.fov_deg = 400.0;
  laser.range_noise_std_m = -0.001;
  laser.dropout_probability = 1.1;
  laser.mixed_pixel_probability = -0.1;
  laser.footprint_rays = 1;
  laser.grazing_dropout_start_deg = 90.0;
  EXPECT_EQ(ProblemKeys(laser.Validate()),
            (std::vector<std::string>{"num_beams", "fov_deg", "range_noise_std_m",
                                      "dropout_probability", "mixed_pixel_probability",
                                      "footprint_rays", "grazing_dropout_start_deg"}));
  EXPECT_THROW(laser.ValidateOrThrow(), ParamError);

  OdometryParams odometry;
  odometry.slip_std_fraction = -1.0;
  EXPECT_EQ(ProblemKeys(odometry.Validate()), (std::vector<std::string>{"slip_std_fraction"}));
}

TEST(SimParamsTest, LaserBeamLayout) {
  const LaserParams laser;
  EXPECT_DOUBLE_EQ(laser.AngleMinRad(), -kPi / 2);
  EXPECT_DOUBLE_EQ(laser.AngleIncrementRad(), kPi / 180);
}

}  // namespace
}  // namespace mjslam::sim
