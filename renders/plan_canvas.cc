#include "renders/plan_canvas.h"

#include <algorithm>
#include <cmath>

namespace mjslam::renders {

PlanCanvas::PlanCanvas(int width, int height, const Eigen::Vector2d& min,
                       const Eigen::Vector2d& max, int margin_px) {
  image_.width = width;
  image_.height = height;
  image_.rgb.assign(static_cast<std::size_t>(width) * height * 3, 255);
  const Eigen::Vector2d size = (max - min).cwiseMax(Eigen::Vector2d(1e-6, 1e-6));
  pixels_per_m_ = std::min((width - 2.0 * margin_px) / size.x(),
                           (height - 2.0 * margin_px) / size.y());
  centre_ = 0.5 * (min + max);
}

Eigen::Vector2d PlanCanvas::PixelOf(const Eigen::Vector2d& p) const {
  return {0.5 * image_.width + (p.x() - centre_.x()) * pixels_per_m_,
          0.5 * image_.height - (p.y() - centre_.y()) * pixels_per_m_};
}

void PlanCanvas::SetPixel(int x, int y, const Rgb& color) {
  if (x < 0 || y < 0 || x >= image_.width || y >= image_.height) return;
  std::uint8_t* pixel = &image_.rgb[(static_cast<std::size_t>(y) * image_.width + x) * 3];
  pixel[0] = color[0];
  pixel[1] = color[1];
  pixel[2] = color[2];
}

void PlanCanvas::Dot(const Eigen::Vector2d& p, const Rgb& color, int radius_px) {
  const Eigen::Vector2d q = PixelOf(p);
  if (!std::isfinite(q.x()) || !std::isfinite(q.y())) return;
  const int cx = static_cast<int>(std::lround(q.x()));
  const int cy = static_cast<int>(std::lround(q.y()));
  for (int y = cy - radius_px; y <= cy + radius_px; ++y) {
    for (int x = cx - radius_px; x <= cx + radius_px; ++x) SetPixel(x, y, color);
  }
}

void PlanCanvas::Segment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Rgb& color,
                         int radius_px) {
  const Eigen::Vector2d pa = PixelOf(a);
  const Eigen::Vector2d pb = PixelOf(b);
  const double length = (pb - pa).norm();
  if (!std::isfinite(length)) return;
  // Steps of at most half a pixel along the segment.
  const int steps = std::min(100000, static_cast<int>(std::ceil(2.0 * length)) + 1);
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector2d q = pa + (pb - pa) * (static_cast<double>(i) / steps);
    const int cx = static_cast<int>(std::lround(q.x()));
    const int cy = static_cast<int>(std::lround(q.y()));
    for (int y = cy - radius_px; y <= cy + radius_px; ++y) {
      for (int x = cx - radius_px; x <= cx + radius_px; ++x) SetPixel(x, y, color);
    }
  }
}

}  // namespace mjslam::renders
