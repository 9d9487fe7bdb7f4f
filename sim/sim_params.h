#pragma once

#include <string>
#include <vector>

#include "common/params.h"

namespace mjslam::sim {

/// Physics settings of the MuJoCo scene (the robot model's <option> holds the
/// rest: integrator, solver, cone) and of the emulated wheel-speed controller:
/// the Pioneer's firmware runs a PID loop on encoder speeds; here each wheel
/// motor gets torque = kp e + ki integral(e), e = set point - wheel speed,
/// clamped to the actuator's ctrlrange (with conditional integration, so the
/// integral does not wind up while the torque is saturated).
struct SimParams {
  /// Physics timestep, seconds. Overrides the model's <option timestep>. The
  /// contact solref time constant (0.02 s) must stay >= 2 timesteps.
  double timestep_s = 0.002;
  /// Time the robot rests on the floor, wheels held still, before time 0 of
  /// the run (contacts settle; the clock is then reset to 0), seconds.
  double settle_time_s = 0.3;
  /// Proportional gain of each wheel's speed controller, N m per rad/s.
  /// With explicit Euler it must stay below about 2 x (wheel inertia +
  /// armature) / timestep (the Simulator checks kp dt / I < 1).
  double wheel_speed_kp_nms_per_rad = 5.0;
  /// Integral gain of each wheel's speed controller, N m per rad of
  /// accumulated speed error (removes the steady-state error under load).
  double wheel_speed_ki_nm_per_rad = 50.0;
  /// The drive's run-to-run variation (floor, tyres, motor controllers),
  /// standard deviation as a fraction: at every control step of a simulated
  /// run the wheel-speed set points are those of the command (v, w) scaled to
  /// (v (1 + e_v), w (1 + e_w)), e_v and e_w drawn independently from
  /// N(0, this) by the run's random stream "sim.drive_disturbance" (so the
  /// runs of a sweep are independent realisations of the motion, as a real
  /// robot's are). The filters are given the command, not the disturbed set
  /// points. 0 (the default): no draws, and the robot's motion is a
  /// deterministic function of its commands, the same in every run that
  /// issues the same commands.
  double drive_disturbance_std_fraction = 0.0;
  /// What that disturbance scales: "twist" (the default) the command's v and
  /// w, each by its own factor, as above; "wheels" each wheel's set point,
  /// left and right by their own factors 1 + e_left, 1 + e_right (drawn in
  /// that order from the same stream), as each wheel's motor controller,
  /// tyre and floor contact vary on their own: then a turn on the spot also
  /// moves the robot forward or back, and driving straight also turns it,
  /// which the twist's factors never do (docs/method.md, "Calibrating the
  /// process noise").
  std::string drive_disturbance = "twist";
  /// The drive's own acceleration limits (a Pioneer's microcontroller ramps
  /// its set points: ARCOS's SETA, SETRA): at every physics step the
  /// twist the wheel set points are made from moves toward the command by at
  /// most these times the timestep, m/s^2 and rad/s^2. 0 (the default): the
  /// set points jump to the command.
  double command_accel_mps2 = 0.0;
  double command_accel_radps2 = 0.0;
  /// The largest world the program sets up, metres: the side of the
  /// smallest axis-aligned square around every static geom's footprint and
  /// the start. Checked when a world is loaded, before any grid over it is
  /// allocated (the contact grid, the true coverage at 0.1 m, the ground
  /// truth at 0.05 m: their memory grows with the square of the side, about
  /// 1 GB at 500 m). At most 2000 (the grids' cell counts stay within int).
  double max_world_extent_m = 500.0;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(timestep_s));
    a->Visit(MJSLAM_NVP(settle_time_s));
    a->Visit(MJSLAM_NVP(wheel_speed_kp_nms_per_rad));
    a->Visit(MJSLAM_NVP(wheel_speed_ki_nm_per_rad));
    a->Visit(MJSLAM_NVP(drive_disturbance_std_fraction));
    a->Visit(MJSLAM_NVP(drive_disturbance));
    a->Visit(MJSLAM_NVP(command_accel_mps2));
    a->Visit(MJSLAM_NVP(command_accel_radps2));
    a->Visit(MJSLAM_NVP(max_world_extent_m));
  }
  std::vector<ParamProblem> Validate() const;
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }
};

/// The differential-drive Pioneer 3-DX as the controllers and the odometry
/// see it. Frame R is the paper's point of control h: on the centre line,
/// `control_point_offset_m` ahead of the axle centre A. Sources of every value:
/// models/README.md. `wheel_radius_m` and `axle_track_m` must agree with the
/// MJCF model (the Simulator checks them to 1 mm and throws otherwise).
struct RobotParams {
  /// Offset `a` of the point of control h (frame R) ahead of the axle centre,
  /// metres (> 0: it is what makes the kinematics of h invertible).
  double control_point_offset_m = 0.2;
  /// Drive wheel radius, metres (195 mm wheels).
  double wheel_radius_m = 0.0975;
  /// Distance between the two drive wheels' contact points, metres.
  double axle_track_m = 0.33;
  /// Largest wheel speed the motors reach, rad/s (1.2 m/s / 0.0975 m).
  double max_wheel_speed_radps = 12.3077;
  /// Largest forward/backward speed of the axle centre, m/s.
  double max_linear_speed_mps = 1.2;
  /// Largest yaw rate, rad/s (300 deg/s).
  double max_angular_speed_radps = 5.235988;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(control_point_offset_m));
    a->Visit(MJSLAM_NVP(wheel_radius_m));
    a->Visit(MJSLAM_NVP(axle_track_m));
    a->Visit(MJSLAM_NVP(max_wheel_speed_radps));
    a->Visit(MJSLAM_NVP(max_linear_speed_mps));
    a->Visit(MJSLAM_NVP(max_angular_speed_radps));
  }
  std::vector<ParamProblem> Validate() const;
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }
};

/// The SICK LMS200 emulation: beam layout, rate, and the noise model applied
/// after the exact cast (see sim/laser_noise.h). The noise fields are kept
/// flat (laser.range_noise_std_m, not laser.noise.range_noise_std_m) so they
/// are easy to set from the command line.
struct LaserParams {
  /// Number of beams, evenly spread over `fov_deg` (both ends included).
  int num_beams = 181;
  /// Field of view, degrees, centred on the x axis of the laser frame S:
  /// beam i is at -fov/2 + i * fov / (num_beams - 1).
  double fov_deg = 180.0;
  /// Maximum range, metres; a beam with no echo within it reports exactly this.
  double max_range_m = 30.0;
  /// Scan rate, Hz. The caller casts at this rate, never on every physics step.
  double rate_hz = 10.0;
  /// Standard deviation of the Gaussian range noise, metres: the truth of the
  /// simulated sensor. What the filters assume is a separate key,
  /// `slam.features.range_noise_std_m` (same default); they differ only when
  /// set apart on purpose, and `mjslam run` prints a note when they do.
  double range_noise_std_m = 0.005;
  /// Systematic range error of every echo: range (1 + s) + b, with the bias
  /// b drawn once per run from N(range_bias_m, range_bias_std_m) and the
  /// scale error s from N(range_scale_fraction, range_scale_std_fraction)
  /// (stream "laser.calibration"). A SICK LMS200's systematic error is of
  /// the order of +-15 mm (its data sheet's "systematic error", Ye and
  /// Borenstein, ICRA 2002). Metres; fraction.
  double range_bias_m = 0.0;
  double range_bias_std_m = 0.0;
  double range_scale_fraction = 0.0;
  double range_scale_std_fraction = 0.0;
  /// Standard deviation of the per-beam angular jitter, degrees: the beam is
  /// cast at its nominal angle plus this error, but reported at the nominal one.
  double angle_jitter_std_deg = 0.0;
  /// Probability that a beam loses its echo (reported as no-return at max
  /// range): the random maximum-range readings of the beam model (Thrun et
  /// al., Sec. 6.3, p_max), whatever the surface.
  double dropout_probability = 0.0;

  // The SICK's error structure (docs/method.md, "The SICK's error
  // structure"; sim/laser_noise.h). Every key off by default: with all of
  // them off the scans are bit for bit those without them.

  /// Range-dependent noise: the Gaussian noise's standard deviation grows to
  /// range_noise_std_m + range_noise_std_per_m * range (metres per metre of
  /// range); the extra part is drawn from stream "laser.range_growth".
  double range_noise_std_per_m = 0.0;
  /// The sensor's range resolution, metres: every echo is reported rounded
  /// to a multiple of it (the LMS200: 0.01 in its cm mode, 0.001 in mm
  /// mode). 0: not rounded.
  double range_resolution_m = 0.0;
  /// Mixed pixels: a beam whose footprint straddles a depth discontinuity
  /// (a sub-ray reads more than mixed_pixel_min_step_m from where the line
  /// through its two neighbours' hits crosses it; on a flat surface, however
  /// grazing, they line up) returns, with this probability (stream
  /// "laser.mixed_pixel"), the mean
  /// of its sub-rays' ranges instead of its centre ray's: a range between
  /// the two surfaces, weighted by how much of the footprint each covers.
  double mixed_pixel_probability = 0.0;
  /// Smallest departure of a sub-ray's range from its neighbours' line that
  /// counts as a depth discontinuity, metres.
  double mixed_pixel_min_step_m = 0.1;
  /// Full angle of the beam's footprint, degrees (its divergence): the
  /// sub-rays of the mixed-pixel model spread over it.
  double beam_divergence_deg = 0.25;
  /// Sub-rays cast across each beam's footprint (only with mixed pixels on).
  int footprint_rays = 5;
  /// Dropouts at grazing incidence: a beam whose angle of incidence theta
  /// (between the beam and the surface's normal) exceeds
  /// grazing_dropout_start_deg loses its echo with probability
  /// grazing_dropout_probability * (theta - start) / (90 deg - start),
  /// rising linearly to grazing_dropout_probability at 90 degrees (stream
  /// "laser.grazing").
  double grazing_dropout_probability = 0.0;
  double grazing_dropout_start_deg = 70.0;

  /// Whether any key of the error structure above is on (then
  /// Simulator::CastLaser casts what sim/laser_footprint.h describes).
  bool HasMixedPixels() const { return mixed_pixel_probability > 0.0; }
  bool HasGrazingDropouts() const { return grazing_dropout_probability > 0.0; }

  /// Bearing of beam 0 in S, radians.
  double AngleMinRad() const;
  /// Angle between consecutive beams, radians.
  double AngleIncrementRad() const;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(num_beams));
    a->Visit(MJSLAM_NVP(fov_deg));
    a->Visit(MJSLAM_NVP(max_range_m));
    a->Visit(MJSLAM_NVP(rate_hz));
    a->Visit(MJSLAM_NVP(range_noise_std_m));
    a->Visit(MJSLAM_NVP(range_bias_m));
    a->Visit(MJSLAM_NVP(range_bias_std_m));
    a->Visit(MJSLAM_NVP(range_scale_fraction));
    a->Visit(MJSLAM_NVP(range_scale_std_fraction));
    a->Visit(MJSLAM_NVP(angle_jitter_std_deg));
    a->Visit(MJSLAM_NVP(dropout_probability));
    a->Visit(MJSLAM_NVP(range_noise_std_per_m));
    a->Visit(MJSLAM_NVP(range_resolution_m));
    a->Visit(MJSLAM_NVP(mixed_pixel_probability));
    a->Visit(MJSLAM_NVP(mixed_pixel_min_step_m));
    a->Visit(MJSLAM_NVP(beam_divergence_deg));
    a->Visit(MJSLAM_NVP(footprint_rays));
    a->Visit(MJSLAM_NVP(grazing_dropout_probability));
    a->Visit(MJSLAM_NVP(grazing_dropout_start_deg));
  }
  std::vector<ParamProblem> Validate() const;
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }
};

/// Wheel encoders and their error model (see sim/wheel_odometry.h).
struct OdometryParams {
  /// Encoder counts per wheel revolution: 500-line encoders read in
  /// quadrature (x4) through the 38.3:1 gearbox = 76600 (models/README.md).
  int ticks_per_wheel_revolution = 76600;
  /// Random slip: standard deviation of a wheel's travel error after 1 m of
  /// travel, as a fraction of that metre. The variance grows linearly with
  /// the distance rolled, so the result does not depend on the update rate.
  double slip_std_fraction = 0.005;
  /// Systematic error: each wheel's effective radius differs from the nominal
  /// one by a factor 1 + e, e drawn once per run from N(mean, this) with the
  /// wheel's mean below (left, then right).
  double wheel_radius_error_std_fraction = 0.0;
  /// Mean of the left and right wheels' radius errors, fractions: a fixed
  /// error the same in every run (e.g. a worn tyre), 0 by default.
  double left_wheel_radius_error_fraction = 0.0;
  double right_wheel_radius_error_fraction = 0.0;
  /// Systematic error of the axle track: the wheels' contact points are
  /// b (1 + e) apart while the odometry assumes b (RobotParams::axle_track_m),
  /// e drawn once per run from N(axle_track_error_fraction, this).
  double axle_track_error_std_fraction = 0.0;
  double axle_track_error_fraction = 0.0;
  /// Slip correlated in time: each wheel's travel is also off by a fraction
  /// that wanders as a first-order Gauss-Markov process over the distance the
  /// wheel rolls (stationary standard deviation this, correlation length
  /// `slip_correlation_distance_m`): a patch of floor, a tyre's load in a
  /// long turn. 0: none.
  double correlated_slip_std_fraction = 0.0;
  double slip_correlation_distance_m = 1.0;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(ticks_per_wheel_revolution));
    a->Visit(MJSLAM_NVP(slip_std_fraction));
    a->Visit(MJSLAM_NVP(wheel_radius_error_std_fraction));
    a->Visit(MJSLAM_NVP(left_wheel_radius_error_fraction));
    a->Visit(MJSLAM_NVP(right_wheel_radius_error_fraction));
    a->Visit(MJSLAM_NVP(axle_track_error_std_fraction));
    a->Visit(MJSLAM_NVP(axle_track_error_fraction));
    a->Visit(MJSLAM_NVP(correlated_slip_std_fraction));
    a->Visit(MJSLAM_NVP(slip_correlation_distance_m));
  }
  std::vector<ParamProblem> Validate() const;
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }
};

}  // namespace mjslam::sim
