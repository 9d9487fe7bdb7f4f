#include "sim/sim_params.h"

#include "common/angles.h"

namespace mjslam::sim {

std::vector<ParamProblem> SimParams::Validate() const {
  ParamChecker check;
  // 0.01 s is half the contact time constant (solref 0.02 s): the upper limit
  // at which MuJoCo's soft contacts stay stable.
  check.InRange("timestep_s", timestep_s, 1e-4, 0.01);
  check.InRange("settle_time_s", settle_time_s, 0.0, 10.0);
  check.Positive("wheel_speed_kp_nms_per_rad", wheel_speed_kp_nms_per_rad);
  check.NonNegative("wheel_speed_ki_nm_per_rad", wheel_speed_ki_nm_per_rad);
  // Beyond a third, 1 + e would often be negative: the wheels would turn backwards.
  check.InRange("drive_disturbance_std_fraction", drive_disturbance_std_fraction, 0.0, 0.3);
  check.OneOf("drive_disturbance", drive_disturbance, {"twist", "wheels"});
  check.NonNegative("command_accel_mps2", command_accel_mps2);
  check.NonNegative("command_accel_radps2", command_accel_radps2);
  check.InRange("max_world_extent_m", max_world_extent_m, 1.0, 2000.0);
  return check.problems();
}

std::vector<ParamProblem> RobotParams::Validate() const {
  ParamChecker check;
  check.Positive("control_point_offset_m", control_point_offset_m);
  check.Positive("wheel_radius_m", wheel_radius_m);
  check.Positive("axle_track_m", axle_track_m);
  check.Positive("max_wheel_speed_radps", max_wheel_speed_radps);
  check.Positive("max_linear_speed_mps", max_linear_speed_mps);
  check.Positive("max_angular_speed_radps", max_angular_speed_radps);
  return check.problems();
}

double LaserParams::AngleMinRad() const { return -0.5 * DegToRad(fov_deg); }

double LaserParams::AngleIncrementRad() const {
  return num_beams > 1 ? DegToRad(fov_deg) / (num_beams - 1) : 0.0;
}

std::vector<ParamProblem> LaserParams::Validate() const {
  ParamChecker check;
  check.InRange("num_beams", num_beams, 2, 100000);
  check.Require(fov_deg > 0.0 && fov_deg <= 360.0, "fov_deg", fov_deg,
                "a value in (0, 360]");
  check.Positive("max_range_m", max_range_m);
  check.Positive("rate_hz", rate_hz);
  check.NonNegative("range_noise_std_m", range_noise_std_m);
  check.Require(range_bias_m > -max_range_m && range_bias_m < max_range_m,
                "range_bias_m", range_bias_m,
                "a value in (-max_range_m, max_range_m)");
  check.InRange("range_bias_std_m", range_bias_std_m, 0.0, 1.0);
  check.InRange("range_scale_fraction", range_scale_fraction, -0.2, 0.2);
  check.InRange("range_scale_std_fraction", range_scale_std_fraction, 0.0, 0.2);
  check.NonNegative("angle_jitter_std_deg", angle_jitter_std_deg);
  check.InRange("dropout_probability", dropout_probability, 0.0, 1.0);
  check.InRange("range_noise_std_per_m", range_noise_std_per_m, 0.0, 0.1);
  check.InRange("range_resolution_m", range_resolution_m, 0.0, 1.0);
  check.InRange("mixed_pixel_probability", mixed_pixel_probability, 0.0, 1.0);
  check.Positive("mixed_pixel_min_step_m", mixed_pixel_min_step_m);
  check.InRange("beam_divergence_deg", beam_divergence_deg, 0.0, 10.0);
  check.InRange("footprint_rays", footprint_rays, 2, 64);
  check.InRange("grazing_dropout_probability", grazing_dropout_probability, 0.0, 1.0);
  check.Require(grazing_dropout_start_deg >= 0.0 && grazing_dropout_start_deg < 90.0,
                "grazing_dropout_start_deg", grazing_dropout_start_deg, "a value in [0, 90)");
  return check.problems();
}

std::vector<ParamProblem> OdometryParams::Validate() const {
  ParamChecker check;
  check.Positive("ticks_per_wheel_revolution", ticks_per_wheel_revolution);
  check.NonNegative("slip_std_fraction", slip_std_fraction);
  check.InRange("wheel_radius_error_std_fraction", wheel_radius_error_std_fraction,
                0.0, 0.2);
  check.InRange("left_wheel_radius_error_fraction", left_wheel_radius_error_fraction, -0.2, 0.2);
  check.InRange("right_wheel_radius_error_fraction", right_wheel_radius_error_fraction, -0.2,
                0.2);
  check.InRange("axle_track_error_std_fraction", axle_track_error_std_fraction, 0.0, 0.2);
  check.InRange("axle_track_error_fraction", axle_track_error_fraction, -0.2, 0.2);
  check.InRange("correlated_slip_std_fraction", correlated_slip_std_fraction, 0.0, 0.2);
  check.Positive("slip_correlation_distance_m", slip_correlation_distance_m);
  return check.problems();
}

}  // namespace mjslam::sim
