#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "common/check.h"
#include "common/interrupt.h"

namespace mjslam {

/// The limits of a 2-D grid of square cells in the world frame W (after
/// Cartographer's mapping/2d/map_limits.h and xy_index.h): the corner of cell
/// (0, 0), the cell size and the number of cells along x and y. Cell (ix, iy)
/// covers [origin + resolution * (ix, iy), origin + resolution * (ix + 1, iy + 1));
/// a world point belongs to the cell its floor falls in. Cells are stored row
/// by row (x fastest): linear index iy * width + ix.
class GridLimits {
 public:
  /// An empty grid (no cells) at the origin with 1 m cells.
  GridLimits() = default;
  /// `resolution_m` > 0; `width`, `height` >= 0 cells.
  GridLimits(const Eigen::Vector2d& origin_W, double resolution_m, int width, int height)
      : origin_W_(origin_W), resolution_m_(resolution_m), width_(width), height_(height) {
    MJSLAM_CHECK(resolution_m > 0.0 && width >= 0 && height >= 0);
  }

  /// World coordinates of the corner of cell (0, 0), metres.
  const Eigen::Vector2d& origin() const { return origin_W_; }
  /// Cell size, metres.
  double resolution() const { return resolution_m_; }
  /// Number of cells along x.
  int width() const { return width_; }
  /// Number of cells along y.
  int height() const { return height_; }
  /// Number of cells.
  int num_cells() const { return width_ * height_; }
  /// World coordinates of the far corner (of cell (width - 1, height - 1)):
  /// origin + resolution * (width, height), metres.
  Eigen::Vector2d far_corner() const {
    return origin_W_ + resolution_m_ * Eigen::Vector2d(width_, height_);
  }

  /// True when (ix, iy) lies inside the grid.
  bool Contains(int ix, int iy) const {
    return ix >= 0 && iy >= 0 && ix < width_ && iy < height_;
  }
  /// True when `cell` lies inside the grid.
  bool Contains(const Eigen::Vector2i& cell) const { return Contains(cell.x(), cell.y()); }
  /// Linear index of cell (ix, iy), which must be inside.
  int Index(int ix, int iy) const { return iy * width_ + ix; }
  /// Cell of a linear index in [0, num_cells()).
  Eigen::Vector2i CellOfIndex(int index) const { return {index % width_, index / width_}; }
  /// Cell containing the world point `p_W`: floor((p_W - origin) / resolution)
  /// (may be outside the grid).
  Eigen::Vector2i CellOf(const Eigen::Vector2d& p_W) const {
    const Eigen::Vector2d q = (p_W - origin_W_) / resolution_m_;
    return {static_cast<int>(std::floor(q.x())), static_cast<int>(std::floor(q.y()))};
  }
  /// World coordinates of the centre of cell (ix, iy):
  /// origin + resolution * (ix + 0.5, iy + 0.5).
  Eigen::Vector2d CellCenter(int ix, int iy) const {
    return origin_W_ + resolution_m_ * Eigen::Vector2d(ix + 0.5, iy + 0.5);
  }

 private:
  Eigen::Vector2d origin_W_ = Eigen::Vector2d::Zero();
  double resolution_m_ = 1.0;
  int width_ = 0;
  int height_ = 0;
};

/// One value of type T per cell of a grid with the given limits. (Use
/// std::uint8_t, not bool, for flags: std::vector<bool> packs bits.)
template <typename T>
class Grid2 {
 public:
  /// An empty grid.
  Grid2() = default;
  /// Every cell of `limits` set to `value`.
  /// Filled in blocks of 2^20 cells, each after a look at the stop request
  /// (a large grid's first touch of its memory takes seconds): throws
  /// Interrupted (common/interrupt.h).
  explicit Grid2(const GridLimits& limits, const T& value = T()) : limits_(limits) {
    const std::size_t n = static_cast<std::size_t>(limits.num_cells());
    cells_.reserve(n);
    constexpr std::size_t kBlock = std::size_t{1} << 20;
    for (std::size_t done = 0; done < n; done += kBlock) {
      ThrowIfInterrupted("grid allocation");
      cells_.insert(cells_.end(), std::min(kBlock, n - done), value);
    }
  }

  /// The grid's limits.
  const GridLimits& limits() const { return limits_; }
  /// Value of cell (ix, iy), which must be inside.
  T& operator()(int ix, int iy) { return cells_[limits_.Index(ix, iy)]; }
  const T& operator()(int ix, int iy) const { return cells_[limits_.Index(ix, iy)]; }
  /// Value of the cell with linear index `index`.
  T& operator[](int index) { return cells_[index]; }
  const T& operator[](int index) const { return cells_[index]; }
  /// All values, row by row (x fastest).
  std::vector<T>& cells() { return cells_; }
  const std::vector<T>& cells() const { return cells_; }
  /// Sets every cell to `value`.
  void Fill(const T& value) { cells_.assign(cells_.size(), value); }

 private:
  GridLimits limits_;
  std::vector<T> cells_;
};

/// Which neighbours of a cell a flood fill enters.
enum class Connectivity {
  /// The 4 cells sharing a side, in the order +x, -x, +y, -y.
  kFour,
  /// The 8 cells sharing a side or a corner, row by row: (-1, -1), (0, -1),
  /// (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1).
  kEight,
};

/// Breadth-first flood fill from `start` (which must be inside and is
/// reached whatever `passable` says of it): enters each neighbour (by
/// `connectivity`, in the order given there) that is inside, not yet marked in
/// `reached` and `passable(ix, iy)`, and marks it. Cells already marked in
/// `reached` on entry are walls too, so successive fills into one `reached`
/// grid find disjoint regions. Returns the linear indices of the cells
/// reached by this fill, in the order of the breadth-first visit. Throws
/// Interrupted (common/interrupt.h) on a stop request (checked every 2^16
/// cells, a few milliseconds).
template <typename Passable>
std::vector<int> FloodFill(const Eigen::Vector2i& start, Connectivity connectivity,
                           const Passable& passable, Grid2<std::uint8_t>* reached) {
  static constexpr int kFourDx[4] = {1, -1, 0, 0};
  static constexpr int kFourDy[4] = {0, 0, 1, -1};
  static constexpr int kEightDx[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
  static constexpr int kEightDy[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
  const GridLimits& limits = reached->limits();
  MJSLAM_CHECK(limits.Contains(start));
  const bool four = connectivity == Connectivity::kFour;
  const int num_neighbours = four ? 4 : 8;
  const int* dx = four ? kFourDx : kEightDx;
  const int* dy = four ? kFourDy : kEightDy;
  std::vector<int> visited;
  const int start_index = limits.Index(start.x(), start.y());
  (*reached)[start_index] = 1;
  std::deque<int> queue = {start_index};
  while (!queue.empty()) {
    const int c = queue.front();
    queue.pop_front();
    visited.push_back(c);
    if ((visited.size() & 0xFFFF) == 0) ThrowIfInterrupted("flood fill");
    const Eigen::Vector2i cell = limits.CellOfIndex(c);
    for (int k = 0; k < num_neighbours; ++k) {
      const int nx = cell.x() + dx[k];
      const int ny = cell.y() + dy[k];
      if (!limits.Contains(nx, ny)) continue;
      const int j = limits.Index(nx, ny);
      if ((*reached)[j] != 0 || !passable(nx, ny)) continue;
      (*reached)[j] = 1;
      queue.push_back(j);
    }
  }
  return visited;
}

/// Visits every cell the segment from `from_W` to `to_W` crosses, in order
/// from the cell of `from_W` to the cell of `to_W` (both included), by the
/// traversal of Amanatides and Woo, "A Fast Voxel Traversal Algorithm for Ray
/// Tracing" (1987), on the cell lattice of `limits` (cells outside the grid
/// are visited too: `visit(ix, iy)` checks). Where the segment passes exactly
/// through a cell corner it steps in y first. At most |dx| + |dy| + 1 cells
/// (in cells between the two end cells) are visited, so rounding can never
/// make it run on.
template <typename Visit>
void TraverseSegment(const GridLimits& limits, const Eigen::Vector2d& from_W,
                     const Eigen::Vector2d& to_W, const Visit& visit) {
  const double r = limits.resolution();
  Eigen::Vector2i cell = limits.CellOf(from_W);
  const Eigen::Vector2i last = limits.CellOf(to_W);
  const Eigen::Vector2d d = to_W - from_W;
  const int step_x = d.x() > 0 ? 1 : -1;
  const int step_y = d.y() > 0 ? 1 : -1;
  const double inf = std::numeric_limits<double>::infinity();
  // Parameter (along d) needed to cross one cell in x and in y.
  const double delta_x = d.x() != 0.0 ? r / std::abs(d.x()) : inf;
  const double delta_y = d.y() != 0.0 ? r / std::abs(d.y()) : inf;
  // Parameter of the first crossing of a cell boundary in x and in y.
  const Eigen::Vector2d corner = limits.origin() + r * cell.cast<double>();
  double t_x = d.x() != 0.0
                   ? ((d.x() > 0 ? corner.x() + r : corner.x()) - from_W.x()) / d.x()
                   : inf;
  double t_y = d.y() != 0.0
                   ? ((d.y() > 0 ? corner.y() + r : corner.y()) - from_W.y()) / d.y()
                   : inf;
  const int max_steps = std::abs(last.x() - cell.x()) + std::abs(last.y() - cell.y());
  for (int k = 0; k <= max_steps; ++k) {
    visit(cell.x(), cell.y());
    if (cell == last) break;
    if (t_x < t_y) {
      cell.x() += step_x;
      t_x += delta_x;
    } else {
      cell.y() += step_y;
      t_y += delta_y;
    }
  }
}

}  // namespace mjslam
