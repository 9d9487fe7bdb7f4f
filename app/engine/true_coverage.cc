#include "app/engine/true_coverage.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "common/check.h"
#include "common/interrupt.h"

namespace mjslam::app {
namespace {

// A cell whose centre is closer than this to an obstacle is not free, metres.
constexpr double kFreeMargin = 0.03;
// The grid extends this far beyond the obstacles, metres.
constexpr double kBorder = 1.0;

}  // namespace

Grid2<double> ClearanceGrid(const std::vector<sim::ObstacleFootprint>& obstacles,
                            const GridLimits& limits, double cutoff_m) {
  // Each obstacle updates only the cells within the cutoff of its bounds, so
  // the cost grows with the obstacles' area, not with obstacles times cells.
  Grid2<double> clearance(limits, std::numeric_limits<double>::infinity());
  for (const sim::ObstacleFootprint& o : obstacles) {
    ThrowIfInterrupted("world setup (coverage grid)");
    Eigen::Vector2d box_lo(o.X_WO.x, o.X_WO.y);
    Eigen::Vector2d box_hi = box_lo;
    if (o.shape == sim::ObstacleFootprint::Shape::kCircle) {
      box_lo.array() -= o.radius_m;
      box_hi.array() += o.radius_m;
    } else {
      for (const Eigen::Vector2d& c : sim::RectangleCorners(o)) {
        box_lo = box_lo.cwiseMin(c);
        box_hi = box_hi.cwiseMax(c);
      }
    }
    const Eigen::Vector2i lo = limits.CellOf(box_lo - Eigen::Vector2d::Constant(cutoff_m));
    const Eigen::Vector2i hi = limits.CellOf(box_hi + Eigen::Vector2d::Constant(cutoff_m));
    for (int j = std::max(0, lo.y()); j <= std::min(limits.height() - 1, hi.y()); ++j) {
      ThrowIfInterrupted("world setup (coverage grid)");
      for (int i = std::max(0, lo.x()); i <= std::min(limits.width() - 1, hi.x()); ++i) {
        clearance(i, j) =
            std::min(clearance(i, j), sim::DistanceToFootprint(limits.CellCenter(i, j), o));
      }
    }
  }
  return clearance;
}

TrueCoverage::TrueCoverage(const std::vector<sim::ObstacleFootprint>& obstacles,
                           const Eigen::Vector2d& p_W_start, double cell_m,
                           double robot_radius_m) {
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
  limits_ = GridLimits(lo - Eigen::Vector2d::Constant(kBorder), cell_m,
                       static_cast<int>(std::ceil((hi.x() - lo.x() + 2 * kBorder) / cell_m)),
                       static_cast<int>(std::ceil((hi.y() - lo.y() + 2 * kBorder) / cell_m)));
  const int width = limits_.width();
  const int height = limits_.height();

  // Clearance of every cell centre; both thresholds below are within the
  // cutoff, so they see the exact clearance.
  const Grid2<double> clearance = ClearanceGrid(obstacles, limits_, robot_radius_m + cell_m);

  // Where the robot can stand, connected to the start.
  const int start = Index(p_W_start);
  MJSLAM_CHECK(start >= 0);
  Grid2<std::uint8_t> standing(limits_, 0);
  FloodFill(
      limits_.CellOfIndex(start), Connectivity::kFour,
      [&](int i, int j) { return clearance(i, j) >= robot_radius_m; }, &standing);

  // Widened by the robot's radius to the free cells beside them.
  // Asked per cell: is a standing cell within the robot's radius (a disk of
  // cell offsets, listed once, the cell itself first)? Most free cells are
  // standing cells themselves, so the disk is searched only near walls.
  const int reach = static_cast<int>(std::ceil(robot_radius_m / cell_m));
  std::vector<Eigen::Vector2i> disk = {Eigen::Vector2i::Zero()};
  for (int dj = -reach; dj <= reach; ++dj) {
    for (int di = -reach; di <= reach; ++di) {
      if ((di != 0 || dj != 0) && std::hypot(di, dj) * cell_m <= robot_radius_m + 1e-9) {
        disk.emplace_back(di, dj);
      }
    }
  }
  reachable_ = Grid2<std::uint8_t>(limits_, 0);
  for (int y = 0; y < height; ++y) {
    ThrowIfInterrupted("world setup (coverage grid)");
    for (int x = 0; x < width; ++x) {
      if (!(clearance(x, y) > kFreeMargin)) continue;
      for (const Eigen::Vector2i& offset : disk) {
        // The disk is symmetric: a standing cell at (x, y) - offset.
        const int i = x - offset.x();
        const int j = y - offset.y();
        if (limits_.Contains(i, j) && standing(i, j)) {
          reachable_(x, y) = 1;
          break;
        }
      }
    }
  }
  num_reachable_ = static_cast<int>(
      std::count(reachable_.cells().begin(), reachable_.cells().end(), 1));
  seen_ = Grid2<std::uint8_t>(limits_, 0);
}

int TrueCoverage::Index(const Eigen::Vector2d& p_W) const {
  const Eigen::Vector2i cell = limits_.CellOf(p_W);
  return limits_.Contains(cell) ? limits_.Index(cell.x(), cell.y()) : -1;
}

void TrueCoverage::Observe(const Pose2& X_WS, const LaserScan& scan) {
  const Eigen::Vector2d p_W = X_WS.translation();
  const double step = 0.5 * limits_.resolution();
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

double TrueCoverage::ReachableArea() const {
  return num_reachable_ * limits_.resolution() * limits_.resolution();
}

}  // namespace mjslam::app
