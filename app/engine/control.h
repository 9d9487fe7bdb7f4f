#pragma once

#include <string>
#include <vector>

#include "common/params.h"
#include "slam/ekf_slam.h"

namespace mjslam::app {

/// Who drives the robot, from which pose, and the paper's control period
/// (docs/method.md, "Control period"). Serialized under `control.*`.
struct ControlParams {
  /// "explorer" (the frontier explorer, closed loop) or "tour" (the built-in
  /// waypoint driver along the world's tour, from the true pose).
  std::string driver = "explorer";
  /// The pose the explorer navigates with: a filter's name (slam.filters;
  /// by default "selective" or "classical"), "odometry" or "ground_truth".
  /// Every filter always runs.
  std::string pose_source = "selective";
  /// Where a filter's processing time per step comes from: "model" (the
  /// deterministic cost model below, bit-reproducible) or "measured" (the
  /// measured time times `measured_time_factor`).
  std::string processing = "model";
  /// Slow-down of the onboard computer emulated with measured times (>= 1 is
  /// slower than this machine).
  double measured_time_factor = 1.0;
  /// Cost model: seconds per scan step for everything but the corrections
  /// (extraction, prediction, association), ...
  double model_base_s = 0.11;
  /// ... plus this many seconds per correction per squared state size (one
  /// correction is O(n^2)). The defaults emulate the paper's onboard
  /// computer: 0.2 s periods for the selective filter, growing to several
  /// tenths for the classical one as the map grows.
  double model_s_per_update_per_n2 = 4e-6;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(driver));
    a->Visit(MJSLAM_NVP(pose_source));
    a->Visit(MJSLAM_NVP(processing));
    a->Visit(MJSLAM_NVP(measured_time_factor));
    a->Visit(MJSLAM_NVP(model_base_s));
    a->Visit(MJSLAM_NVP(model_s_per_update_per_n2));
  }
  std::vector<ParamProblem> Validate() const;
};

/// A filter's processing time for one step, seconds: the cost model of
/// `params` on the step's report, or `measured_us` scaled. A step without a
/// scan (prediction only) costs nothing in the model.
double ProcessingSeconds(const ControlParams& params, const slam::StepReport& report,
                         bool has_scan, double measured_us);

/// The paper's command period: the base period (one control step, `dt_s`)
/// times ceil(processing / dt), at least one step. Returns the number of
/// control steps the last command is held.
int CommandPeriodSteps(double processing_s, double dt_s);

}  // namespace mjslam::app
