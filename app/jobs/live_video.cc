#include "app/jobs/live_video.h"

#include <algorithm>
#include <chrono>

#include "app/jobs/scene_frame.h"
#include "sim/scene.h"
#include "app/engine/filter_bank.h"
#include "rundir/layout.h"
#include "slam/filter.h"

namespace mjslam::app {
LiveVideo::LiveVideo(const RunConfig& config, const std::string& run_dir)
    : params_(config.render),
      renderer_(sim::Scene(config.run.world, config.run.robot_model), config.sim, config.robot,
                config.render.width, config.render.height),
      video_(rundir::PathIn(run_dir, rundir::kVideoFile), config.render.width,
             config.render.height, config.render.fps, config.render.crf) {
  min_step_m_ = PixelSizeM(renderer_);
  frame_.ellipse_scale = params_.ellipse_scale;
  frame_.filters = FilterLayers(slam::FilterNamesOf(config.slam));
}

void LiveVideo::Step(double t_s, const Pose2& X_WR_true, const FilterBank& slam,
                     const LaserScan* scan, const Pose2& X_WS,
                     const explorer::Explorer* explorer) {
  frame_.t_s = t_s;
  frame_.X_WR_true = X_WR_true;
  AppendPathPoint(&frame_.true_path, X_WR_true.translation(), min_step_m_);
  for (int i = 0; i < slam.size(); ++i) {
    renders::FilterLayer& layer = frame_.filters[i];
    const Pose2 X_WR = slam.filter(i).X_WR();
    AppendPathPoint(&layer.path, X_WR.translation(), min_step_m_);
    layer.X_WR = X_WR;
    layer.P_xy = slam.filter(i).pose_covariance().topLeftCorner<2, 2>();
    // A submap that began this step: its start, where the filter is now.
    if (slam.filter(i).SubmapStartTimes().size() > layer.submap_starts.size()) {
      layer.submap_starts.push_back(X_WR);
    }
  }
  if (scan != nullptr) {
    frame_.laser_hits = LaserHits(X_WS, scan->ranges_m, scan->max_range_m, scan->angle_min_rad,
                                  scan->angle_increment_rad);
  }
  if (t_s + 1e-9 < next_frame_t_s_) return;

  // A frame is due: the maps and the explorer as they are now.
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < slam.size(); ++i) SetMapLayer(slam.filter(i).Map(), &frame_.filters[i]);
  frame_.explorer.reset();
  if (explorer != nullptr) {
    renders::ExplorerLayer layer;
    layer.frontier = explorer->frontier_points();
    layer.goal = explorer->goal();
    for (const explorer::PathPoint& point : explorer->path()) layer.path.push_back(point.p_W);
    frame_.explorer = layer;
  }
  const renders::Image image = renderer_.Render(frame_);
  const double frame_dt = params_.speedup / params_.fps;
  while (next_frame_t_s_ <= t_s + 1e-9) {  // frames faster than the steps repeat
    video_.AddFrame(image);
    next_frame_t_s_ = video_.frames() * frame_dt;
  }
  wall_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int LiveVideo::Finish() {
  video_.Finish();
  return video_.frames();
}

}  // namespace mjslam::app
