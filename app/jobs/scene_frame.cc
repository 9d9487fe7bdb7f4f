#include "app/jobs/scene_frame.h"

#include <algorithm>
#include <cmath>

#include "renders/filter_colors.h"

namespace mjslam::app {

std::vector<renders::FilterLayer> FilterLayers(const std::vector<std::string>& names) {
  const std::vector<std::array<float, 3>> colors = renders::FilterColors(names);
  std::vector<renders::FilterLayer> layers(names.size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    layers[i].name = names[i];
    layers[i].color = colors[i];
  }
  return layers;
}

double PixelSizeM(const renders::SceneRenderer& renderer) {
  const double pixels_per_m =
      std::abs(renderer.PixelOf({0.0, 0.0}).x() - renderer.PixelOf({1.0, 0.0}).x());
  return 1.0 / std::max(pixels_per_m, 1e-9);
}

void AppendPathPoint(std::vector<Eigen::Vector2d>* path, const Eigen::Vector2d& p_W,
                     double min_step_m, bool force) {
  if (path->empty() || (p_W - path->back()).norm() >= min_step_m || force) path->push_back(p_W);
}

void SetMapLayer(const eval::Map& map, renders::FilterLayer* layer) {
  layer->lines.clear();
  layer->corners.clear();
  for (const MapFeature& feature : map) {
    if (feature.type == MapFeature::Type::kCorner) {
      layer->corners.push_back(feature.params);
    } else if (feature.has_segment) {
      layer->lines.push_back({feature.p_WA, feature.p_WB});
    }
  }
}

std::vector<Eigen::Vector2d> LaserHits(const Pose2& X_WS, const std::vector<double>& ranges_m,
                                       double max_range_m, double angle_min_rad,
                                       double angle_increment_rad) {
  std::vector<Eigen::Vector2d> hits;
  for (std::size_t i = 0; i < ranges_m.size(); ++i) {
    const double range = ranges_m[i];
    if (!(range < max_range_m)) continue;
    const double bearing = angle_min_rad + static_cast<double>(i) * angle_increment_rad;
    hits.push_back(X_WS * Eigen::Vector2d(range * std::cos(bearing), range * std::sin(bearing)));
  }
  return hits;
}

}  // namespace mjslam::app
