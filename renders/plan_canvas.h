#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "renders/image.h"

namespace mjslam::renders {

/// An RGB colour.
using Rgb = std::array<std::uint8_t, 3>;

/// A plan view drawn without OpenGL: points and segments of the world plane
/// onto an image, world x to the right and y up, at one scale for both axes
/// (the window is fitted inside the image and centred). For what has no
/// MuJoCo world to render, such as a real log (app/jobs/render_real.h).
class PlanCanvas {
 public:
  /// A white image of `width` x `height` pixels showing at least the window
  /// [min, max] of the world plane (metres), plus `margin_px` on every side.
  PlanCanvas(int width, int height, const Eigen::Vector2d& min, const Eigen::Vector2d& max,
             int margin_px = 10);

  /// The pixel (column, row from the top) of world point `p`, unrounded.
  Eigen::Vector2d PixelOf(const Eigen::Vector2d& p) const;
  /// A filled square of side 2 `radius_px` + 1 centred on `p`; pixels
  /// outside the image are left out.
  void Dot(const Eigen::Vector2d& p, const Rgb& color, int radius_px = 0);
  /// A segment from `a` to `b`, `radius_px` thick on each side.
  void Segment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Rgb& color,
               int radius_px = 0);

  const Image& image() const { return image_; }
  Image& image() { return image_; }

 private:
  void SetPixel(int x, int y, const Rgb& color);

  Image image_;
  Eigen::Vector2d centre_;
  double pixels_per_m_ = 1.0;
};

}  // namespace mjslam::renders
