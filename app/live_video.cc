#include "app/live_video.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace mjslam::app {
namespace {

// Keeps a point once it is at least `min_step_m` from the last one kept.
void Append(std::vector<Eigen::Vector2d>* path, const Eigen::Vector2d& p, double min_step_m) {
  if (path->empty() || (p - path->back()).norm() >= min_step_m) path->push_back(p);
}

}  // namespace

LiveVideo::LiveVideo(const RunConfig& config, const std::string& run_dir)
    : params_(config.render),
      renderer_(config.run.world, config.run.robot_model, config.sim, config.robot,
                config.render.width, config.render.height),
      video_(run_dir + "/video.mp4", config.render.width, config.render.height, config.render.fps,
             config.render.crf) {
  // Paths keep a point once it is a pixel away from the last one kept.
  const double pixels_per_m =
      std::abs(renderer_.PixelOf({0.0, 0.0}).x() - renderer_.PixelOf({1.0, 0.0}).x());
  min_step_m_ = 1.0 / std::max(pixels_per_m, 1e-9);
  frame_.ellipse_scale = params_.ellipse_scale;
  for (const auto& [name, color] :
       {std::pair<std::string, renders::Rgb>{"classical", renders::colors::kClassical},
        std::pair<std::string, renders::Rgb>{"selective", renders::colors::kSelective}}) {
    renders::FilterLayer layer;
    layer.name = name;
    layer.color = color;
    frame_.filters.push_back(layer);
  }
}

void LiveVideo::Step(double t_s, const Pose2& X_WR_true, const SlamPair& slam,
                     const LaserScan* scan, const Pose2& X_WS,
                     const explorer::Explorer* explorer) {
  frame_.t_s = t_s;
  frame_.X_WR_true = X_WR_true;
  Append(&frame_.true_path, X_WR_true.translation(), min_step_m_);
  for (int i = 0; i < 2; ++i) {
    renders::FilterLayer& layer = frame_.filters[i];
    const Pose2 X_WR = slam.filter(i).X_WR();
    Append(&layer.path, X_WR.translation(), min_step_m_);
    layer.X_WR = X_WR;
    layer.P_xy = slam.filter(i).pose_covariance().topLeftCorner<2, 2>();
  }
  if (scan != nullptr) {
    frame_.laser_hits.clear();
    for (int b = 0; b < scan->size(); ++b) {
      if (!scan->has_return[b]) continue;
      const double range = scan->ranges_m[b];
      const double bearing = scan->BeamAngle(b);
      frame_.laser_hits.push_back(X_WS * Eigen::Vector2d(range * std::cos(bearing),
                                                         range * std::sin(bearing)));
    }
  }
  if (t_s + 1e-9 < next_frame_t_s_) return;

  // A frame is due: the maps and the explorer as they are now.
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 2; ++i) {
    renders::FilterLayer& layer = frame_.filters[i];
    layer.lines.clear();
    layer.corners.clear();
    for (const slam::MapFeature& feature : slam.filter(i).Map()) {
      if (feature.type == slam::FeatureType::kCorner) {
        layer.corners.push_back(feature.params);
      } else if (feature.has_segment) {
        layer.lines.push_back({feature.p_WA, feature.p_WB});
      }
    }
  }
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
