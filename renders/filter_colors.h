#pragma once

#include <array>
#include <string>
#include <vector>

namespace mjslam::renders {

/// The colour of each filter of `names`, in order, red, green, blue in 0..1,
/// as every render and plot draws it (renders/report.py's colors_of):
/// classical orange and selective blue (colors::kClassical, kSelective of
/// scene_renderer.h), any other the next of a fixed palette in turn (teal,
/// brown, olive, pink, grey). Plain arrays, so that a PlanCanvas user (whose
/// Rgb is bytes) can take them too.
std::vector<std::array<float, 3>> FilterColors(const std::vector<std::string>& names);

}  // namespace mjslam::renders
