#include "explorer/frontiers.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "common/angles.h"
#include "common/check.h"
#include "common/grid2.h"

namespace mjslam::explorer {
namespace {

// Whether a cell stops a gain ray: it or one of its 4-neighbours is occupied.
bool BlocksRay(const OccupancyGrid& grid, int ix, int iy) {
  return grid.State(ix, iy) == CellState::kOccupied ||
         grid.State(ix + 1, iy) == CellState::kOccupied ||
         grid.State(ix - 1, iy) == CellState::kOccupied ||
         grid.State(ix, iy + 1) == CellState::kOccupied ||
         grid.State(ix, iy - 1) == CellState::kOccupied;
}

}  // namespace

std::vector<Eigen::Vector2d> LocalFrontierPoints(const LaserScan& scan, const Pose2& X_WS,
                                                 const ExplorerParams& params) {
  std::vector<Eigen::Vector2d> points;
  const int n = scan.size();
  const Eigen::Vector2d p_WS = X_WS.translation();
  auto open = [&](int i) {
    return scan.has_return[i] == 0 || scan.ranges_m[i] >= scan.max_range_m ||
           scan.ranges_m[i] > params.max_insert_range_m;
  };
  auto direction = [&](int i) {
    const double th = X_WS.theta + scan.BeamAngle(i);
    return Eigen::Vector2d(std::cos(th), std::sin(th));
  };
  // Moves a point toward the laser by the standoff (not past the laser).
  auto pull_back = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2d to_laser = p_WS - p;
    const double d = to_laser.norm();
    if (d < 1e-9) return p;
    return Eigen::Vector2d(p + std::min(params.frontier_standoff_m, 0.5 * d) / d * to_laser);
  };

  // Openings between consecutive echoes.
  for (int i = 0; i + 1 < n; ++i) {
    if (open(i) || open(i + 1)) continue;
    const Eigen::Vector2d a = p_WS + scan.ranges_m[i] * direction(i);
    const Eigen::Vector2d b = p_WS + scan.ranges_m[i + 1] * direction(i + 1);
    if ((a - b).norm() >= params.min_opening_m) points.push_back(pull_back(0.5 * (a + b)));
  }
  // Runs of open beams.
  const double free_range = std::min(params.no_return_free_range_m, params.max_insert_range_m);
  int i = 0;
  while (i < n) {
    if (!open(i)) {
      ++i;
      continue;
    }
    int j = i;
    while (j + 1 < n && open(j + 1)) ++j;
    const double width = free_range * std::abs(scan.angle_increment_rad) * (j - i + 1);
    if (width >= params.min_opening_m) {
      const int middle = (i + j) / 2;
      points.push_back(p_WS + std::max(0.0, free_range - params.frontier_standoff_m) *
                                  direction(middle));
    }
    i = j + 1;
  }
  return points;
}

std::vector<Eigen::Vector2d> GlobalFrontierPoints(const OccupancyGrid& grid,
                                                  const ExplorerParams& params) {
  const int w = grid.width();
  const int h = grid.height();
  std::vector<Eigen::Vector2d> points;
  if (w == 0) return points;
  // Frontier cells: free, with an unknown 4-neighbour.
  Grid2<std::uint8_t> frontier(grid.limits(), 0);
  for (int iy = 0; iy < h; ++iy) {
    for (int ix = 0; ix < w; ++ix) {
      if (grid.State(ix, iy) != CellState::kFree) continue;
      frontier(ix, iy) = grid.State(ix + 1, iy) == CellState::kUnknown ||
                         grid.State(ix - 1, iy) == CellState::kUnknown ||
                         grid.State(ix, iy + 1) == CellState::kUnknown ||
                         grid.State(ix, iy - 1) == CellState::kUnknown;
    }
  }
  // Clusters (8-connected, breadth first), cut into pieces of about 1 m.
  const int piece_cells = std::max(1, static_cast<int>(std::lround(1.0 / grid.resolution())));
  Grid2<std::uint8_t> seen(grid.limits(), 0);
  for (int start = 0; start < w * h; ++start) {
    if (!frontier[start] || seen[start]) continue;
    const std::vector<int> cluster = FloodFill(
        grid.limits().CellOfIndex(start), Connectivity::kEight,
        [&](int ix, int iy) { return frontier(ix, iy) != 0; }, &seen);
    if (static_cast<int>(cluster.size()) < params.min_frontier_cells) continue;
    for (size_t first = 0; first < cluster.size(); first += piece_cells) {
      const size_t last = std::min(cluster.size(), first + piece_cells);
      Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
      for (size_t k = first; k < last; ++k) {
        centroid += grid.CellCenter(cluster[k] % w, cluster[k] / w);
      }
      centroid /= double(last - first);
      Eigen::Vector2d best = grid.CellCenter(cluster[first] % w, cluster[first] / w);
      for (size_t k = first; k < last; ++k) {
        const Eigen::Vector2d p = grid.CellCenter(cluster[k] % w, cluster[k] / w);
        if ((p - centroid).squaredNorm() < (best - centroid).squaredNorm()) best = p;
      }
      points.push_back(best);
    }
  }
  return points;
}

// The rays march in steps of half a cell and neighbouring rays cross the
// same cells, so a cell is visited several times: a ray's repeat of the cell
// it just tested is skipped (same answer), and each unknown cell is counted
// once through a stamp over the box of cells the rays can reach. Same count,
// bit for bit, as testing every sample and sorting the cells
// (tests/explorer/frontiers_test.cc checks it against that). With a finite
// `stop_at_m2`, it returns as soon as the area counted so far reaches it
// (the count only grows, so "at least stop_at_m2" is then decided).
namespace {

double CountGain(const OccupancyGrid& grid, const Eigen::Vector2d& p_W, double radius_m,
                 double stop_at_m2) {
  const double r = grid.resolution();
  const int num_rays = std::max(16, static_cast<int>(std::ceil(2.0 * kPi * radius_m / r)));
  const int steps = static_cast<int>(std::ceil(radius_m / (0.5 * r)));
  // The rays' directions, as computed for each ray before (kept per thread
  // for the last ray count, which is fixed by the params).
  thread_local std::vector<Eigen::Vector2d> directions;
  if (static_cast<int>(directions.size()) != num_rays) {
    directions.resize(num_rays);
    for (int k = 0; k < num_rays; ++k) {
      const double th = 2.0 * kPi * k / num_rays;
      directions[k] = Eigen::Vector2d(std::cos(th), std::sin(th));
    }
  }
  // Every sample lies within radius_m of p_W, so within reach + 1 cells of
  // its cell (floor's rounding); two cells of margin. A cell outside the box
  // (never expected) is still counted once, through `outside`.
  const int reach = static_cast<int>(std::ceil(radius_m / r)) + 2;
  const Eigen::Vector2i center = grid.CellOf(p_W);
  const int side = 2 * reach + 1;
  thread_local std::vector<std::uint8_t> counted;
  counted.assign(static_cast<std::size_t>(side) * side, 0);
  std::vector<long long> outside;
  long long unique = 0;
  for (int k = 0; k < num_rays; ++k) {
    const Eigen::Vector2d& u = directions[k];
    Eigen::Vector2i previous(std::numeric_limits<int>::min(), 0);
    for (int j = 1; j <= steps; ++j) {
      const Eigen::Vector2i c = grid.CellOf(p_W + (radius_m * j / steps) * u);
      if (c == previous) continue;
      previous = c;
      if (BlocksRay(grid, c.x(), c.y())) break;
      if (grid.State(c.x(), c.y()) != CellState::kUnknown) continue;
      const int bx = c.x() - center.x() + reach;
      const int by = c.y() - center.y() + reach;
      if (bx >= 0 && bx < side && by >= 0 && by < side) {
        std::uint8_t& stamp = counted[static_cast<std::size_t>(by) * side + bx];
        if (stamp != 0) continue;
        stamp = 1;
        ++unique;
        if (unique * r * r >= stop_at_m2) return unique * r * r;
      } else {
        outside.push_back((static_cast<long long>(c.y()) << 32) ^ static_cast<unsigned int>(c.x()));
      }
    }
  }
  std::sort(outside.begin(), outside.end());
  unique += std::unique(outside.begin(), outside.end()) - outside.begin();
  return unique * r * r;
}

}  // namespace

double InformationGain(const OccupancyGrid& grid, const Eigen::Vector2d& p_W, double radius_m) {
  return CountGain(grid, p_W, radius_m, std::numeric_limits<double>::infinity());
}

bool HasInformationGain(const OccupancyGrid& grid, const Eigen::Vector2d& p_W, double radius_m,
                        double min_gain_m2) {
  return CountGain(grid, p_W, radius_m, min_gain_m2) >= min_gain_m2;
}

double GainCache::Gain(const OccupancyGrid& grid, const Eigen::Vector2d& p_W, double radius_m) {
  MJSLAM_CHECK(radius_m_ < 0.0 || radius_m_ == radius_m);
  radius_m_ = radius_m;
  const std::vector<OccupancyGrid::LatticeBox>& changes = grid.state_changes();
  std::pair<std::uint64_t, std::uint64_t> key;
  std::memcpy(&key.first, &p_W.x(), sizeof(double));
  std::memcpy(&key.second, &p_W.y(), sizeof(double));
  const auto it = entries_.find(key);
  if (it != entries_.end()) {
    Entry& entry = it->second;
    bool changed = false;
    for (std::size_t k = entry.changes_checked; k < changes.size() && !changed; ++k) {
      changed = (changes[k].lo.array() <= entry.reads.hi.array()).all() &&
                (entry.reads.lo.array() <= changes[k].hi.array()).all();
    }
    if (!changed) {
      entry.changes_checked = changes.size();
      return entry.gain_m2;
    }
  }
  // CountGain reads the cells within its box's reach of the point's cell
  // and, through BlocksRay, one more.
  const int reach = static_cast<int>(std::ceil(radius_m / grid.resolution())) + 3;
  const Eigen::Vector2i center = grid.CellOf(p_W) + grid.lattice_origin();
  const double gain = InformationGain(grid, p_W, radius_m);
  entries_[key] = Entry{gain,
                        {center - Eigen::Vector2i::Constant(reach),
                         center + Eigen::Vector2i::Constant(reach)},
                        changes.size()};
  return gain;
}

}  // namespace mjslam::explorer
