#include "renders/render_params.h"

#include <cmath>
#include <stdexcept>

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

int RenderParams::NumVideoFrames(double duration_s) const {
  if (!(duration_s >= 0.0 && std::isfinite(duration_s))) {
    throw std::runtime_error("video of a run of " + ValueText(duration_s) +
                             " s: expected a finite duration >= 0");
  }
  const double frames = std::floor(duration_s * fps / speedup + 1e-9) + 1.0;
  if (!(frames <= kMaxVideoFrames)) {
    throw std::runtime_error("render.speedup = " + ValueText(speedup) + " and render.fps = " +
                             ValueText(fps) + " give " + ValueText(frames) + " video frames for " +
                             ValueText(duration_s) + " s (at most " + ValueText(kMaxVideoFrames) +
                             "): raise the speedup");
  }
  return static_cast<int>(frames);
}

}  // namespace mjslam::renders
