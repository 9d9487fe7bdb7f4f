#include "renders/render_params.h"

namespace mjslam::renders {

std::vector<ParamProblem> RenderParams::Validate() const {
  ParamChecker check;
  check.InRange("width", width, 16, 7680);
  check.InRange("height", height, 16, 4320);
  check.Require(width % 2 == 0, "width", width, "an even number of pixels (H.264 4:2:0)");
  check.Require(height % 2 == 0, "height", height, "an even number of pixels (H.264 4:2:0)");
  check.InRange("fps", fps, 1.0, 240.0);
  check.Positive("speedup", speedup);
  check.InRange("crf", crf, 0, 51);
  check.InRange("ellipse_scale", ellipse_scale, 1.0, 1000.0);
  return check.problems();
}

}  // namespace mjslam::renders
