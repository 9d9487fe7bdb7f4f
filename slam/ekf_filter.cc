#include "slam/ekf_filter.h"

namespace mjslam::slam {

CorrectionMode CorrectionModeFromName(const std::string& update) {
  if (update == "classical") return CorrectionMode::kClassical;
  if (update == "selective") return CorrectionMode::kSelective;
  throw ParamError("update: expected classical or selective (got " + update + ")");
}

EkfFilter::EkfFilter(const FilterSettings& settings, const Pose2& X_WR0, const Pose2& X_RS,
                     Rng rng)
    : ekf_(settings.slam.ekf, CorrectionModeFromName(settings.filter.update), X_WR0, X_RS,
           std::move(rng)) {}

}  // namespace mjslam::slam
