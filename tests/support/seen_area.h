#pragma once

// Test-only ground truth of exploration: the reachable free area of a world
// of walls (0.1 m cells whose centres are at least 0.08 m from every wall,
// flood-filled, 4-connected, from the start), and the part of it that exact
// laser beams have crossed.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "common/grid2.h"
#include "common/laser_scan.h"
#include "common/pose2.h"
#include "common/segments.h"
#include "tests/support/walls.h"

namespace mjslam::testing {

class SeenArea {
 public:
  SeenArea(const std::vector<Wall>& walls, const Eigen::Vector2d& p_W_start) {
    Eigen::Vector2d lo = p_W_start;
    Eigen::Vector2d hi = p_W_start;
    for (const Wall& wall : walls) {
      lo = lo.cwiseMin(wall.a).cwiseMin(wall.b);
      hi = hi.cwiseMax(wall.a).cwiseMax(wall.b);
    }
    lo.array() -= 0.5;
    hi.array() += 0.5;
    limits_ = GridLimits(lo, kCell, static_cast<int>(std::ceil((hi.x() - lo.x()) / kCell)),
                         static_cast<int>(std::ceil((hi.y() - lo.y()) / kCell)));
    reachable_ = Grid2<std::uint8_t>(limits_, 0);
    seen_ = Grid2<std::uint8_t>(limits_, 0);
    // Cells clear of every wall.
    Grid2<std::uint8_t> clear(limits_, 1);
    for (const Wall& wall : walls) {
      const Eigen::Vector2d e = wall.b - wall.a;
      const int n = std::max(1, static_cast<int>(std::ceil(e.norm() / (0.5 * kCell))));
      for (int k = 0; k <= n; ++k) {
        const Eigen::Vector2i c = limits_.CellOf(wall.a + (double(k) / n) * e);
        for (int iy = c.y() - 2; iy <= c.y() + 2; ++iy) {
          for (int ix = c.x() - 2; ix <= c.x() + 2; ++ix) {
            if (!limits_.Contains(ix, iy)) continue;
            if (PointSegmentDistance(limits_.CellCenter(ix, iy), wall.a, wall.b) < 0.08) {
              clear(ix, iy) = 0;
            }
          }
        }
      }
    }
    // Flood fill from the start.
    FloodFill(
        limits_.CellOf(p_W_start), Connectivity::kFour,
        [&clear](int ix, int iy) { return clear(ix, iy) != 0; }, &reachable_);
  }

  /// Marks the cells crossed by the beams of an exact scan taken at `X_WS`.
  void Add(const LaserScan& scan, const Pose2& X_WS) {
    for (int i = 0; i < scan.size(); ++i) {
      const double th = X_WS.theta + scan.BeamAngle(i);
      const Eigen::Vector2d u(std::cos(th), std::sin(th));
      for (double s = 0.0; s <= scan.ranges_m[i]; s += 0.04) {
        const Eigen::Vector2i c = limits_.CellOf(X_WS.translation() + s * u);
        if (limits_.Contains(c)) seen_(c.x(), c.y()) = 1;
      }
    }
  }

  /// Seen part of the reachable free area, 0..1.
  double Fraction() const {
    int total = 0;
    int seen = 0;
    for (int i = 0; i < limits_.num_cells(); ++i) {
      total += reachable_[i];
      seen += reachable_[i] && seen_[i];
    }
    return total == 0 ? 0.0 : double(seen) / total;
  }
  /// Reachable free area, m^2.
  double ReachableArea() const {
    int total = 0;
    for (const std::uint8_t r : reachable_.cells()) total += r;
    return total * kCell * kCell;
  }

 private:
  static constexpr double kCell = 0.1;

  GridLimits limits_;
  Grid2<std::uint8_t> reachable_;
  Grid2<std::uint8_t> seen_;
};

}  // namespace mjslam::testing
