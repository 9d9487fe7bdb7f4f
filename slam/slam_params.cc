#include "slam/slam_params.h"

#include <cmath>
#include <iterator>
#include <vector>

namespace mjslam::slam {
namespace {

// The index of `name` in `names`; throws ParamError naming `key` if absent.
template <std::size_t N>
int IndexOfName(const char* const (&names)[N], const std::string& name, const char* key) {
  for (std::size_t i = 0; i < N; ++i) {
    if (name == names[i]) return static_cast<int>(i);
  }
  ParamChecker check;
  check.OneOf(key, name, std::vector<std::string>(names, names + N));
  ThrowIfProblems(check.problems(), "slam.ekf");
  return -1;  // not reached: the check above failed
}

}  // namespace

MotionIntegration MotionIntegrationFromName(const std::string& name) {
  return static_cast<MotionIntegration>(
      IndexOfName(kMotionIntegrationNames, name, "process_model.integration"));
}

JacobianPoint JacobianPointFromName(const std::string& name) {
  return static_cast<JacobianPoint>(IndexOfName(kJacobianPointNames, name, "jacobians"));
}

SelectionPolicy SelectionPolicyFromName(const std::string& name) {
  return static_cast<SelectionPolicy>(
      IndexOfName(kSelectionPolicyNames, name, "selection_policy"));
}

std::vector<ParamProblem> CommandNoiseParams::Validate() const {
  ParamChecker check;
  check.NonNegative("v_std_mps", v_std_mps);
  check.NonNegative("v_fraction", v_fraction);
  check.NonNegative("w_std_radps", w_std_radps);
  check.NonNegative("w_fraction", w_fraction);
  check.NonNegative("change_fraction", change_fraction);
  // A zero constant part would make a stopped robot's prediction exact.
  check.Require(v_std_mps > 0.0 || w_std_radps > 0.0, "v_std_mps", v_std_mps,
                "a value > 0 when w_std_radps is 0");
  return check.problems();
}

std::vector<ParamProblem> OdometryNoiseParams::Validate() const {
  ParamChecker check;
  check.NonNegative("distance_std_m", distance_std_m);
  check.NonNegative("distance_std_m_per_sqrt_m", distance_std_m_per_sqrt_m);
  check.NonNegative("distance_std_m_per_sqrt_rad", distance_std_m_per_sqrt_rad);
  check.NonNegative("heading_std_rad", heading_std_rad);
  check.NonNegative("heading_std_rad_per_sqrt_m", heading_std_rad_per_sqrt_m);
  check.NonNegative("heading_std_rad_per_sqrt_rad", heading_std_rad_per_sqrt_rad);
  return check.problems();
}

std::vector<ParamProblem> LateralMotionParams::Validate() const {
  ParamChecker check;
  check.NonNegative("slip_std_m_per_rad", slip_std_m_per_rad);
  check.NonNegative("slip_std_m_per_sqrt_m", slip_std_m_per_sqrt_m);
  check.NonNegative("skid_s", skid_s);
  return check.problems();
}

std::vector<ParamProblem> SelfCalibrationParams::Validate() const {
  ParamChecker check;
  check.InRange("distance_scale_std", distance_scale_std, 0.0, 0.5);
  check.InRange("heading_scale_std", heading_scale_std, 0.0, 0.5);
  check.InRange("heading_per_m_std_rad", heading_per_m_std_rad, 0.0, 1.0);
  check.InRange("range_bias_std_m", range_bias_std_m, 0.0, 1.0);
  check.InRange("range_scale_std", range_scale_std, 0.0, 0.5);
  check.InRange("wheel_slip_drift_std_per_sqrt_m", wheel_slip_drift_std_per_sqrt_m, 0.0, 0.5);
  return check.problems();
}

std::vector<ParamProblem> EkfParams::Validate() const {
  ParamChecker check;
  check.Merge("process_model", ValidateProcessModel(process_model));
  check.Positive("control_point_offset_m", control_point_offset_m);
  check.Positive("axle_track_m", axle_track_m);
  check.Require(std::isfinite(control_point_offset_m), "control_point_offset_m",
                control_point_offset_m, "a finite value");
  check.Merge("self_calibration", self_calibration.Validate());
  check.OneOf("jacobians", jacobians,
              std::vector<std::string>(std::begin(kJacobianPointNames),
                                       std::end(kJacobianPointNames)));
  check.NonNegative("initial_position_std_m", initial_position_std_m);
  check.NonNegative("initial_heading_std_rad", initial_heading_std_rad);
  check.NonNegative("extra_line_rho_std_m", extra_line_rho_std_m);
  check.NonNegative("extra_line_alpha_std_rad", extra_line_alpha_std_rad);
  check.NonNegative("extra_corner_range_std_m", extra_corner_range_std_m);
  check.NonNegative("extra_corner_bearing_std_rad", extra_corner_bearing_std_rad);
  check.NonNegative("line_match_max_gap_m", line_match_max_gap_m);
  check.NonNegative("duplicate_line_distance_m", duplicate_line_distance_m);
  check.Positive("duplicate_line_min_overlap_m", duplicate_line_min_overlap_m);
  check.Require(gate_probability > 0.0 && gate_probability < 1.0, "gate_probability",
                gate_probability, "a probability in (0, 1)");
  check.Require(new_feature_probability >= gate_probability && new_feature_probability < 1.0,
                "new_feature_probability", new_feature_probability,
                "a probability in [gate_probability, 1)");
  check.Require(max_updates >= 1, "max_updates", max_updates, "a value >= 1");
  check.OneOf("selection_policy", selection_policy,
              std::vector<std::string>(std::begin(kSelectionPolicyNames),
                                       std::end(kSelectionPolicyNames)));
  return check.problems();
}

}  // namespace mjslam::slam
