#pragma once

#include "common/map_feature.h"

namespace mjslam::eval {

/// A map as eval takes it (a filter's estimate or the ground truth): the
/// program's one map type, common/map_feature.h.
using Map = FeatureMap;

}  // namespace mjslam::eval
