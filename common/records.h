#pragma once

#include "common/laser_scan.h"
#include "common/pose2.h"

namespace mjslam {

/// Velocity command or estimate for frame R (the point of control h):
/// linear speed along the heading and angular speed.
struct Twist2 {
  double v_mps = 0.0;
  double w_radps = 0.0;
};

/// What the robot reports at one control step: the plain record that the SLAM
/// consumes, from the simulator or from a recorded log.
struct SensorRecord {
  /// Time of the record, seconds since the start of the run.
  double t_s = 0.0;
  /// Time since the previous record, seconds (0 for the first).
  double dt_s = 0.0;
  /// The command that was applied to the robot during the last `dt_s`.
  Twist2 command;
  /// Wheel-odometry pose of frame R in a fixed odometry frame O, integrated
  /// from the wheel encoders (mjslam places O so that X_OR starts at the true
  /// start pose in W; the filters use only its increments).
  Pose2 X_OR;
  /// Whether `scan` holds a new sweep.
  bool has_scan = false;
  /// The laser sweep as the SLAM receives it (with noise), in frame S.
  LaserScan scan;
};

}  // namespace mjslam
