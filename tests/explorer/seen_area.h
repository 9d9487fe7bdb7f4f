#pragma once

// Test-only ground truth of exploration: the reachable free area of a world
// of walls (0.1 m cells whose centres are at least 0.08 m from every wall,
// flood-filled from the start), and the part of it that exact laser beams
// have crossed.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <vector>

#include "common/laser_scan.h"
#include "common/pose2.h"
#include "tests/explorer/kinematic_sim.h"

namespace mjslam::explorer::testing {

class SeenArea {
 public:
  SeenArea(const std::vector<Wall>& walls, const Eigen::Vector2d& p_W_start) {
    lo_ = p_W_start;
    Eigen::Vector2d hi = p_W_start;
    for (const Wall& wall : walls) {
      lo_ = lo_.cwiseMin(wall.a).cwiseMin(wall.b);
      hi = hi.cwiseMax(wall.a).cwiseMax(wall.b);
    }
    lo_.array() -= 0.5;
    hi.array() += 0.5;
    width_ = static_cast<int>(std::ceil((hi.x() - lo_.x()) / kCell));
    height_ = static_cast<int>(std::ceil((hi.y() - lo_.y()) / kCell));
    reachable_.assign(width_ * height_, 0);
    seen_.assign(width_ * height_, 0);
    // Cells clear of every wall.
    std::vector<std::uint8_t> clear(width_ * height_, 1);
    for (const Wall& wall : walls) {
      const Eigen::Vector2d e = wall.b - wall.a;
      const int n = std::max(1, static_cast<int>(std::ceil(e.norm() / (0.5 * kCell))));
      for (int k = 0; k <= n; ++k) {
        const Eigen::Vector2d p = wall.a + (double(k) / n) * e;
        const int cx = CellX(p.x());
        const int cy = CellY(p.y());
        for (int iy = cy - 2; iy <= cy + 2; ++iy) {
          for (int ix = cx - 2; ix <= cx + 2; ++ix) {
            if (!Inside(ix, iy)) continue;
            const double t =
                std::clamp((Center(ix, iy) - wall.a).dot(e) / e.squaredNorm(), 0.0, 1.0);
            if ((wall.a + t * e - Center(ix, iy)).norm() < 0.08) clear[iy * width_ + ix] = 0;
          }
        }
      }
    }
    // Flood fill from the start.
    const int sx = CellX(p_W_start.x());
    const int sy = CellY(p_W_start.y());
    std::deque<int> queue = {sy * width_ + sx};
    reachable_[queue.front()] = 1;
    while (!queue.empty()) {
      const int c = queue.front();
      queue.pop_front();
      const int cx = c % width_;
      const int cy = c / width_;
      const int dx[4] = {1, -1, 0, 0};
      const int dy[4] = {0, 0, 1, -1};
      for (int k = 0; k < 4; ++k) {
        const int nx = cx + dx[k];
        const int ny = cy + dy[k];
        if (!Inside(nx, ny)) continue;
        const int j = ny * width_ + nx;
        if (clear[j] && !reachable_[j]) {
          reachable_[j] = 1;
          queue.push_back(j);
        }
      }
    }
  }

  /// Marks the cells crossed by the beams of an exact scan taken at `X_WS`.
  void Add(const LaserScan& scan, const Pose2& X_WS) {
    for (int i = 0; i < scan.size(); ++i) {
      const double th = X_WS.theta + scan.BeamAngle(i);
      const Eigen::Vector2d u(std::cos(th), std::sin(th));
      for (double s = 0.0; s <= scan.ranges_m[i]; s += 0.04) {
        const Eigen::Vector2d p = X_WS.translation() + s * u;
        const int ix = CellX(p.x());
        const int iy = CellY(p.y());
        if (Inside(ix, iy)) seen_[iy * width_ + ix] = 1;
      }
    }
  }

  /// Seen part of the reachable free area, 0..1.
  double Fraction() const {
    int total = 0;
    int seen = 0;
    for (size_t i = 0; i < reachable_.size(); ++i) {
      total += reachable_[i];
      seen += reachable_[i] && seen_[i];
    }
    return total == 0 ? 0.0 : double(seen) / total;
  }
  /// Reachable free area, m^2.
  double ReachableArea() const {
    int total = 0;
    for (const std::uint8_t r : reachable_) total += r;
    return total * kCell * kCell;
  }

 private:
  static constexpr double kCell = 0.1;
  int CellX(double x) const { return static_cast<int>(std::floor((x - lo_.x()) / kCell)); }
  int CellY(double y) const { return static_cast<int>(std::floor((y - lo_.y()) / kCell)); }
  bool Inside(int ix, int iy) const { return ix >= 0 && iy >= 0 && ix < width_ && iy < height_; }
  Eigen::Vector2d Center(int ix, int iy) const {
    return lo_ + kCell * Eigen::Vector2d(ix + 0.5, iy + 0.5);
  }

  Eigen::Vector2d lo_;
  int width_ = 0;
  int height_ = 0;
  std::vector<std::uint8_t> reachable_;
  std::vector<std::uint8_t> seen_;
};

}  // namespace mjslam::explorer::testing
