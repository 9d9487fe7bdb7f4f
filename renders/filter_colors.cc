#include "renders/filter_colors.h"

#include <iterator>

#include "renders/scene_renderer.h"

namespace mjslam::renders {

std::vector<std::array<float, 3>> FilterColors(const std::vector<std::string>& names) {
  // The other filters' colours, in turn: teal, brown, olive, pink, grey.
  static const Rgb kOthers[] = {{0.00f, 0.60f, 0.60f},
                                {0.55f, 0.30f, 0.10f},
                                {0.50f, 0.55f, 0.00f},
                                {0.95f, 0.40f, 0.65f},
                                {0.50f, 0.50f, 0.50f}};
  std::vector<std::array<float, 3>> out;
  std::size_t next_other = 0;
  for (const std::string& name : names) {
    if (name == "classical") {
      out.push_back(colors::kClassical);
    } else if (name == "selective") {
      out.push_back(colors::kSelective);
    } else {
      out.push_back(kOthers[next_other++ % std::size(kOthers)]);
    }
  }
  return out;
}

}  // namespace mjslam::renders
