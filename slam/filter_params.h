#pragma once

// One entry of `slam.filters` (slam/filter.h has the interface and registry).
#include <string>
#include <vector>

#include "common/params.h"

namespace mjslam::slam {

/// One entry of `slam.filters`: a named filter of a kind, with the settings
/// of its own. Serialized under `slam.filters[i]`.
struct FilterParams {
  /// The filter's name in the run directory (columns `<name>_x`, ...,
  /// map_<name>.csv, summary.json's filters.<name>) and in
  /// control.pose_source: lower-case letters, digits and '_', starting with
  /// a letter; not odometry or ground_truth.
  std::string name;
  /// The registered kind (FilterRegistry): "ekf" (EKF-SLAM, EkfSlam),
  /// "submaps" (EKF-SLAM in submaps joined into a global map, SubmapFilter)
  /// or a kind another library registers (examples/).
  std::string kind = "ekf";
  /// Kinds ekf and submaps: "classical" (Algorithm 1) or "selective"
  /// (Algorithm 2).
  std::string update;
  /// MAX of Algorithm 2; 0: slam.ekf.max_updates.
  int max_updates = 0;
  /// The selective filter's choice (slam.ekf.selection_policy's values);
  /// "": slam.ekf.selection_policy.
  std::string selection_policy;
  /// "every_scan" or "realtime" (slam.timing's values); "": slam.timing.
  std::string timing;
  /// Scales every standard deviation of slam.ekf.process_model.noise (of
  /// either kind) for this filter (> 0; 1: slam.ekf's noise as it is).
  double process_noise_scale = 1.0;
  /// Kind submaps: a submap is closed and joined into the global map when
  /// it holds this many features (>= 1).
  int submap_max_features = 60;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(name));
    a->Visit(MJSLAM_NVP(kind));
    a->Visit(MJSLAM_NVP(update));
    a->Visit(MJSLAM_NVP(max_updates));
    a->Visit(MJSLAM_NVP(selection_policy));
    a->Visit(MJSLAM_NVP(timing));
    a->Visit(MJSLAM_NVP(process_noise_scale));
    a->Visit(MJSLAM_NVP(submap_max_features));
  }
  /// The problems of this entry alone (keys relative to it): the name's
  /// form, a registered kind, kind ekf's update, the ranges.
  std::vector<ParamProblem> Validate() const;
};

/// The problems of a `slam.filters` list, keys `filters[i].<key>`: each
/// entry's (FilterParams::Validate), and a name given twice.
std::vector<ParamProblem> ValidateFilters(const std::vector<FilterParams>& filters);

}  // namespace mjslam::slam
