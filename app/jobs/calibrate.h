#pragma once

// mjslam calibrate: the filters' odometry noise fitted to runs with a true
// pose (docs/method.md, "Calibration"), through the motion model the filters
// predict with (slam/motion_model.h).
#include <string>
#include <vector>

#include "common/pose2.h"
#include "slam/slam_params.h"

namespace mjslam::app {

/// One run's poses at its records: time, true pose and wheel-odometry pose
/// of R (trajectory.csv's t, true_*, odom_*).
struct RunMotion {
  std::string name;
  std::vector<double> t_s;
  std::vector<Pose2> X_WR_true;
  std::vector<Pose2> X_OR;
};

/// A run's systematic odometry errors, least squares over its records, in
/// the terms of self-calibration (SelfCalibrationParams): distance scale
/// q_d, heading scale q_th and heading change per metre k.
struct RunSystematics {
  std::string name;
  int records = 0;
  double distance_scale = 0.0;
  double heading_scale = 0.0;
  double heading_per_m_rad = 0.0;
};

/// The mean of (error)^2 / (model variance) of one component over windows
/// of a number of records (1 when the model is right; above 1: the model
/// understates the error).
struct WindowCheck {
  int window_records = 0;
  int windows = 0;
  double distance = 0.0;
  double heading = 0.0;
  double lateral = 0.0;
};

struct Calibration {
  /// The model given with its process model replaced by the fitted one, of
  /// kind odometry: its noise and lateral motion fitted, its integration
  /// the given one's.
  slam::EkfParams fitted;
  std::vector<RunSystematics> runs;
  /// The checks of the model given and of the fitted one, for windows of
  /// 1, `window_records` and 5 x `window_records` records.
  std::vector<WindowCheck> given_checks;
  std::vector<WindowCheck> fitted_checks;
  int records = 0;
};

/// Fits the odometry noise of `model` (its offset a and track B are used as
/// they are; its process model is the given one when of kind odometry, else
/// the built-in odometry model) to the runs' records, in three steps:
///   1. each record's input error: the increments (d, dth) that
///      slam::OdometryInput gives for the true motion less those of the
///      odometry, and the true motion's lateral offset across the mid-arc
///      heading that slam::PredictPose leaves;
///   2. per run, the systematic part, least squares: d -> q_d d + k B^2/4
///      dth, dth -> q_th dth + k d (what self-calibration estimates), and
///      the skid (process_model.lateral.skid_s) pooled over the runs; both
///      removed;
///   3. the variances of OdometryNoiseParams (per metre and per radian; the
///      floors per record are set to 0) and the lateral slip fitted,
///      non-negative, to the remaining errors summed over windows of
///      `window_records` records (iteratively reweighted least squares of
///      the squared sums: errors correlated over a window count as such);
///      windows in which the robot does not move are left out.
/// Throws std::invalid_argument when a run has a record that is not finite,
/// times that do not increase, or when there are fewer than 50 windows.
Calibration Calibrate(const std::vector<RunMotion>& runs, const slam::EkfParams& model,
                      int window_records);

/// The run directories of `paths`: each path that holds a trajectory.csv,
/// and for a sweep directory (runs/run_*/trajectory.csv) its runs, sorted.
/// Throws std::runtime_error naming a path that is neither.
std::vector<std::string> RunDirectories(const std::vector<std::string>& paths);

/// Reads the true and odometry poses of a run directory's trajectory.csv.
/// Throws std::runtime_error naming the file when it holds no true pose (an
/// imported log).
RunMotion ReadRunMotion(const std::string& run_dir);

/// The YAML of a config that sets the fitted process model of
/// `calibration` whole (`slam.ekf.process_model`, kind odometry: its
/// integration, noise and lateral motion), on top of `base` (a path written
/// as given; empty: no base), with a header naming the runs.
std::string CalibrationYaml(const Calibration& calibration, const std::string& base,
                            const std::string& header);

/// A table of the fit for the terminal: the keys (given and fitted), the
/// window checks and the runs' systematic errors.
std::string CalibrationReport(const Calibration& calibration, const slam::EkfParams& given);

}  // namespace mjslam::app
