#include "app/engine/control.h"

#include <algorithm>
#include <cmath>

namespace mjslam::app {

std::vector<ParamProblem> ControlParams::Validate() const {
  ParamChecker check;
  check.OneOf("driver", driver, {"explorer", "tour"});
  // pose_source (a filter's name, odometry or ground_truth): checked by
  // RunConfig::Validate, which knows the filters' names.
  check.OneOf("processing", processing, {"model", "measured"});
  check.Positive("measured_time_factor", measured_time_factor);
  check.NonNegative("model_base_s", model_base_s);
  check.NonNegative("model_s_per_update_per_n2", model_s_per_update_per_n2);
  return check.problems();
}

double ProcessingSeconds(const ControlParams& params, const slam::StepReport& report,
                         bool has_scan, double measured_us) {
  if (params.processing == "measured") return measured_us * 1e-6 * params.measured_time_factor;
  if (!has_scan) return 0.0;
  if (report.correction_cost_n2 >= 0.0) {
    return params.model_base_s + params.model_s_per_update_per_n2 * report.correction_cost_n2;
  }
  const double n = 3.0 + 2.0 * report.num_features;
  return params.model_base_s + params.model_s_per_update_per_n2 * report.num_updated * n * n;
}

int CommandPeriodSteps(double processing_s, double dt_s) {
  // A relative tolerance keeps an exact multiple (0.2 s / 0.1 s) at 2.
  const double steps = std::ceil(processing_s / dt_s - 1e-9);
  return std::max(1, static_cast<int>(steps));
}

}  // namespace mjslam::app
