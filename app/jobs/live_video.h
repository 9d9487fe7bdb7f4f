#pragma once

#include <memory>
#include <optional>
#include <string>

#include "app/engine/run_config.h"
#include "app/engine/filter_bank.h"
#include "common/laser_scan.h"
#include "explorer/explorer.h"
#include "renders/scene_renderer.h"
#include "renders/video_writer.h"

namespace mjslam::app {

/// The video of a run rendered as it goes (`mjslam run` with render.enabled
/// and render.video): one frame every `speedup / fps` simulated seconds,
/// drawn from the run's state at that step, so the filters' maps grow in the
/// video as they do in the filters. Written to RUN_DIR/video.mp4 through a
/// temporary file; a run that stops before Finish() leaves no video.
class LiveVideo {
 public:
  LiveVideo(const RunConfig& config, const std::string& run_dir);

  /// Records the step at time `t_s` (true pose of R, the filters, the
  /// scan of the step at the true laser pose X_WS if any, the explorer if it
  /// drives) and renders the frames that fall due.
  void Step(double t_s, const Pose2& X_WR_true, const FilterBank& filters, const LaserScan* scan,
            const Pose2& X_WS, const explorer::Explorer* explorer);

  /// Closes the video; returns the number of frames.
  int Finish();
  /// Wall time spent rendering and encoding so far, seconds.
  double wall_s() const { return wall_s_; }

 private:
  renders::RenderParams params_;
  renders::SceneRenderer renderer_;
  renders::VideoWriter video_;
  renders::SceneFrame frame_;
  double min_step_m_ = 0.0;
  double next_frame_t_s_ = 0.0;
  double wall_s_ = 0.0;
};

}  // namespace mjslam::app
