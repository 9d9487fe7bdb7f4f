#include "app/true_coverage.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "common/check.h"

namespace mjslam::app {
namespace {

// A cell whose centre is closer than this to an obstacle is not free, metres.
constexpr double kFreeMargin = 0.03;
// The grid extends this far beyond the obstacles, metres.
constexpr double kBorder = 1.0;

}  // namespace

TrueCoverage::TrueCoverage(const std::vector<sim::ObstacleFootprint>& obstacles,
                           const Eigen::Vector2d& p_W_start, double cell_m,
                           double robot_radius_m)
    : cell_m_(cell_m) {
  MJSLAM_CHECK(cell_m > 0.0 && robot_radius_m > 0.0);
  // Bounding box of the obstacles and the start.
  Eigen::Vector2d lo = p_W_start;
  Eigen::Vector2d hi = p_W_start;
  for (const sim::ObstacleFootprint& o : obstacles) {
    const double r = o.shape == sim::ObstacleFootprint::Shape::kCircle
                         ? o.radius_m
                         : o.half_extents_m.norm();
    lo = lo.cwiseMin(Eigen::Vector2d(o.X_WO.x - r, o.X_WO.y - r));
    hi = hi.cwiseMax(Eigen::Vector2d(o.X_WO.x + r, o.X_WO.y + r));
  }
  origin_W_ = lo - Eigen::Vector2d::Constant(kBorder);
  width_ = static_cast<int>(std::ceil((hi.x() - lo.x() + 2 * kBorder) / cell_m));
  height_ = static_cast<int>(std::ceil((hi.y() - lo.y() + 2 * kBorder) / cell_m));
  const int num_cells = width_ * height_;

  // Clearance of every cell centre.
  std::vector<double> clearance(num_cells);
  for (int j = 0; j < height_; ++j) {
    for (int i = 0; i < width_; ++i) {
      const Eigen::Vector2d c = origin_W_ + cell_m * Eigen::Vector2d(i + 0.5, j + 0.5);
      clearance[j * width_ + i] = sim::DistanceToObstacles(c, obstacles);
    }
  }

  // Where the robot can stand, connected to the start.
  std::vector<std::uint8_t> standing(num_cells, 0);
  std::deque<int> queue;
  const int start = Index(p_W_start);
  MJSLAM_CHECK(start >= 0);
  standing[start] = 1;
  queue.push_back(start);
  while (!queue.empty()) {
    const int k = queue.front();
    queue.pop_front();
    const int i = k % width_;
    const int j = k / width_;
    const int neighbours[4][2] = {{i + 1, j}, {i - 1, j}, {i, j + 1}, {i, j - 1}};
    for (const auto& n : neighbours) {
      if (n[0] < 0 || n[1] < 0 || n[0] >= width_ || n[1] >= height_) continue;
      const int m = n[1] * width_ + n[0];
      if (standing[m] || clearance[m] < robot_radius_m) continue;
      standing[m] = 1;
      queue.push_back(m);
    }
  }

  // Widened by the robot's radius to the free cells beside them.
  const int reach = static_cast<int>(std::ceil(robot_radius_m / cell_m));
  reachable_.assign(num_cells, 0);
  for (int j = 0; j < height_; ++j) {
    for (int i = 0; i < width_; ++i) {
      if (!standing[j * width_ + i]) continue;
      for (int dj = -reach; dj <= reach; ++dj) {
        for (int di = -reach; di <= reach; ++di) {
          const int x = i + di;
          const int y = j + dj;
          if (x < 0 || y < 0 || x >= width_ || y >= height_) continue;
          if (std::hypot(di, dj) * cell_m > robot_radius_m + 1e-9) continue;
          const int m = y * width_ + x;
          if (clearance[m] > kFreeMargin) reachable_[m] = 1;
        }
      }
    }
  }
  num_reachable_ = static_cast<int>(std::count(reachable_.begin(), reachable_.end(), 1));
  seen_.assign(num_cells, 0);
}

int TrueCoverage::Index(const Eigen::Vector2d& p_W) const {
  const Eigen::Vector2d g = (p_W - origin_W_) / cell_m_;
  const int i = static_cast<int>(std::floor(g.x()));
  const int j = static_cast<int>(std::floor(g.y()));
  if (i < 0 || j < 0 || i >= width_ || j >= height_) return -1;
  return j * width_ + i;
}

void TrueCoverage::Observe(const Pose2& X_WS, const LaserScan& scan) {
  const Eigen::Vector2d p_W = X_WS.translation();
  const double step = 0.5 * cell_m_;
  for (int b = 0; b < scan.size(); ++b) {
    const double range = std::min(scan.ranges_m[b], scan.max_range_m);
    const double bearing = X_WS.theta + scan.BeamAngle(b);
    const Eigen::Vector2d u(std::cos(bearing), std::sin(bearing));
    for (double s = 0.0; s <= range; s += step) {
      const int k = Index(p_W + s * u);
      if (k < 0) break;
      if (!seen_[k]) {
        seen_[k] = 1;
        if (reachable_[k]) ++num_seen_reachable_;
      }
    }
  }
}

double TrueCoverage::ExploredFraction() const {
  return num_reachable_ == 0 ? 0.0 : static_cast<double>(num_seen_reachable_) / num_reachable_;
}

double TrueCoverage::ReachableArea() const { return num_reachable_ * cell_m_ * cell_m_; }

}  // namespace mjslam::app
