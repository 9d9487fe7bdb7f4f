#pragma once

#include <string>
#include <vector>

#include "common/params.h"

namespace mjslam::renders {

/// How a run is rendered: the images, the video and the plots that `mjslam
/// render` (and `mjslam run`, when `enabled`) leaves in a run directory.
/// Serialized under `render.*`.
struct RenderParams {
  /// `mjslam run` renders the run directory at the end of a completed run.
  /// `mjslam render` ignores it.
  bool enabled = false;
  /// Size of final.png and of the video frames, pixels. Even numbers (H.264
  /// with 4:2:0 chroma needs them).
  int width = 640;
  int height = 480;
  /// Frame rate of video.mp4, frames per second of video.
  double fps = 30.0;
  /// Simulated seconds per second of video (3: a 120 s run plays in 40 s).
  double speedup = 3.0;
  /// Write video.mp4 (else only final.png, the plots and index.html).
  bool video = true;
  /// Write the plots and index.html (python3 with matplotlib).
  bool plots = true;
  /// H.264 constant rate factor of the video (0 lossless .. 51 worst; 23 is
  /// x264's default).
  int crf = 23;
  /// The 2-sigma position ellipses are drawn this many times their size
  /// (they are millimetres to centimetres across; a pixel of a 640 x 480
  /// view of a 13 m world covers 2-3 cm). The legend states the factor.
  double ellipse_scale = 100.0;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(enabled));
    a->Visit(MJSLAM_NVP(width));
    a->Visit(MJSLAM_NVP(height));
    a->Visit(MJSLAM_NVP(fps));
    a->Visit(MJSLAM_NVP(speedup));
    a->Visit(MJSLAM_NVP(video));
    a->Visit(MJSLAM_NVP(plots));
    a->Visit(MJSLAM_NVP(crf));
    a->Visit(MJSLAM_NVP(ellipse_scale));
  }
  std::vector<ParamProblem> Validate() const;
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }

  /// Frames of a video of `duration_s` simulated seconds: one per
  /// speedup / fps seconds, plus the last. Throws std::runtime_error naming
  /// render.speedup, render.fps and the count when it exceeds kMaxVideoFrames
  /// or `duration_s` is not finite and >= 0.
  int NumVideoFrames(double duration_s) const;
};

/// Most frames a video may have: 1e6 frames are over 9 hours at 30 frames/s
/// and hours of rendering; more is a mistaken speedup (1e-6), not a video.
inline constexpr int kMaxVideoFrames = 1000000;

}  // namespace mjslam::renders
