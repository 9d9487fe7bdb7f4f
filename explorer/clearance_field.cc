#include "explorer/clearance_field.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/check.h"

namespace mjslam::explorer {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Squared distance standing for "no occupied cell", cells^2. Sums of it and
// squared cell distances stay exact in double precision.
constexpr double kFar = 1e12;

// One-dimensional squared Euclidean distance transform of f[0, n) into
// d[0, n) (Felzenszwalb and Huttenlocher 2012, Algorithm 1); `v` and `z` are
// scratch space of n and n + 1 entries. With integer inputs every result is
// the exact integer minimum over the samples.
void DistanceTransform1d(const double* f, int n, double* d, int* v, double* z) {
  int k = 0;
  v[0] = 0;
  z[0] = -kInfinity;
  z[1] = kInfinity;
  for (int q = 1; q < n; ++q) {
    double s = 0.0;
    while (true) {
      s = ((f[q] + double(q) * q) - (f[v[k]] + double(v[k]) * v[k])) / (2.0 * q - 2.0 * v[k]);
      if (s <= z[k] && k > 0) {
        --k;
      } else {
        break;
      }
    }
    if (s <= z[k]) {  // k == 0: replace the only parabola
      v[0] = q;
      z[0] = -kInfinity;
      z[1] = kInfinity;
      continue;
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = kInfinity;
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < q) ++k;
    d[q] = (double(q) - v[k]) * (double(q) - v[k]) + f[v[k]];
  }
}

bool SameLimits(const GridLimits& a, const GridLimits& b) {
  return a.width() == b.width() && a.height() == b.height() && a.origin() == b.origin() &&
         a.resolution() == b.resolution();
}

}  // namespace

ClearanceField::ClearanceField(double cap_m) : cap_m_(cap_m), cap_cells_(0) {
  MJSLAM_CHECK(cap_m > 0.0);
}

std::size_t ClearanceField::Recompute(const OccupancyGrid& grid) {
  limits_ = grid.limits();
  lattice_origin_ = grid.lattice_origin();
  cap_cells_ = static_cast<int>(std::ceil(cap_m_ / grid.resolution()));
  occupied_ = Grid2<std::uint8_t>(limits_, 0);
  clearance_ = Grid2<float>(limits_, static_cast<float>(cap_m_));
  for (int iy = 0; iy < limits_.height(); ++iy) {
    for (int ix = 0; ix < limits_.width(); ++ix) {
      occupied_(ix, iy) = grid.State(ix, iy) == CellState::kOccupied;
    }
  }
  tiles_x_ = (limits_.width() + kTileCells - 1) / kTileCells;
  tiles_y_ = (limits_.height() + kTileCells - 1) / kTileCells;
  dirty_.assign(static_cast<size_t>(tiles_x_) * tiles_y_, 0);
  changes_read_ = grid.occupancy_changes().size();
  RecomputeBox(0, 0, limits_.width(), limits_.height());
  return static_cast<std::size_t>(limits_.num_cells());
}

std::size_t ClearanceField::Update(const OccupancyGrid& grid) {
  if (!SameLimits(limits_, grid.limits())) Resize(grid);
  // The cells that changed state since the last call, and the tiles within
  // the cap of them.
  const std::vector<Eigen::Vector2i>& changes = grid.occupancy_changes();
  const int c = cap_cells_;
  for (; changes_read_ < changes.size(); ++changes_read_) {
    const Eigen::Vector2i cell = changes[changes_read_] - lattice_origin_;
    MJSLAM_CHECK(limits_.Contains(cell));
    occupied_(cell.x(), cell.y()) = grid.State(cell.x(), cell.y()) == CellState::kOccupied;
    MarkDirty(cell.x() - c, cell.y() - c, cell.x() + c, cell.y() + c);
  }
  return RecomputeDirty();
}

void ClearanceField::Resize(const OccupancyGrid& grid) {
  const GridLimits old_limits = limits_;
  const Grid2<std::uint8_t> old_occupied = std::move(occupied_);
  const Grid2<float> old_clearance = std::move(clearance_);
  limits_ = grid.limits();
  cap_cells_ = static_cast<int>(std::ceil(cap_m_ / grid.resolution()));
  occupied_ = Grid2<std::uint8_t>(limits_, 0);
  clearance_ = Grid2<float>(limits_, static_cast<float>(cap_m_));
  tiles_x_ = (limits_.width() + kTileCells - 1) / kTileCells;
  tiles_y_ = (limits_.height() + kTileCells - 1) / kTileCells;
  dirty_.assign(static_cast<size_t>(tiles_x_) * tiles_y_, 0);
  // The grid only grows, by whole cells: the old cells sit at an offset.
  const Eigen::Vector2i offset = lattice_origin_ - grid.lattice_origin();
  lattice_origin_ = grid.lattice_origin();
  const int w0 = old_limits.width();
  const int h0 = old_limits.height();
  if (w0 == 0 || h0 == 0) return;
  MJSLAM_CHECK(offset.x() >= 0 && offset.y() >= 0 && offset.x() + w0 <= limits_.width() &&
               offset.y() + h0 <= limits_.height());
  for (int iy = 0; iy < h0; ++iy) {
    for (int ix = 0; ix < w0; ++ix) {
      occupied_(ix + offset.x(), iy + offset.y()) = old_occupied(ix, iy);
      clearance_(ix + offset.x(), iy + offset.y()) = old_clearance(ix, iy);
    }
  }
  // The old values stay right (the new cells are not occupied); the new
  // cells within the cap of the old ones are recomputed: four strips.
  const int c = cap_cells_;
  const int x0 = offset.x();
  const int y0 = offset.y();
  const int x1 = x0 + w0 - 1;
  const int y1 = y0 + h0 - 1;
  if (x0 > 0) MarkDirty(x0 - c, y0 - c, x0 - 1, y1 + c);
  if (x1 + 1 < limits_.width()) MarkDirty(x1 + 1, y0 - c, x1 + c, y1 + c);
  if (y0 > 0) MarkDirty(x0, y0 - c, x1, y0 - 1);
  if (y1 + 1 < limits_.height()) MarkDirty(x0, y1 + 1, x1, y1 + c);
}

void ClearanceField::MarkDirty(int x0, int y0, int x1, int y1) {
  x0 = std::max(x0, 0);
  y0 = std::max(y0, 0);
  x1 = std::min(x1, limits_.width() - 1);
  y1 = std::min(y1, limits_.height() - 1);
  if (x0 > x1 || y0 > y1) return;
  for (int ty = y0 / kTileCells; ty <= y1 / kTileCells; ++ty) {
    for (int tx = x0 / kTileCells; tx <= x1 / kTileCells; ++tx) dirty_[ty * tiles_x_ + tx] = 1;
  }
}

std::size_t ClearanceField::RecomputeDirty() {
  std::size_t cells = 0;
  for (int ty = 0; ty < tiles_y_; ++ty) {
    int tx = 0;
    while (tx < tiles_x_) {
      if (!dirty_[ty * tiles_x_ + tx]) {
        ++tx;
        continue;
      }
      // A run of dirty tiles in this row, recomputed as one box.
      const int run_start = tx;
      while (tx < tiles_x_ && dirty_[ty * tiles_x_ + tx]) dirty_[ty * tiles_x_ + tx++] = 0;
      const int x0 = run_start * kTileCells;
      const int x1 = std::min(limits_.width(), tx * kTileCells);
      const int y0 = ty * kTileCells;
      const int y1 = std::min(limits_.height(), (ty + 1) * kTileCells);
      RecomputeBox(x0, y0, x1, y1);
      cells += static_cast<std::size_t>(x1 - x0) * (y1 - y0);
    }
  }
  return cells;
}

void ClearanceField::RecomputeBox(int x0, int y0, int x1, int y1) {
  if (x0 >= x1 || y0 >= y1) return;
  // The input: the box grown by the cap (an occupied cell farther away
  // cannot bring a cell of the box below the cap).
  const int c = cap_cells_;
  const int ix0 = std::max(0, x0 - c);
  const int ix1 = std::min(limits_.width(), x1 + c);
  const int iy0 = std::max(0, y0 - c);
  const int iy1 = std::min(limits_.height(), y1 + c);
  const int w = ix1 - ix0;
  const int h = iy1 - iy0;
  const int rows = y1 - y0;
  const int n = std::max(w, h);
  f_.resize(n);
  d_.resize(n);
  v_.resize(n);
  z_.resize(n + 1);
  // Columns over the input rows, kept for the rows of the box only. A
  // column without an occupied cell transforms to kFar everywhere (each
  // sample is its own nearest, exactly), so it is filled, not transformed.
  squared_.resize(static_cast<size_t>(w) * rows);
  bool any_occupied = false;
  for (int ix = ix0; ix < ix1; ++ix) {
    bool column_occupied = false;
    for (int iy = iy0; iy < iy1; ++iy) {
      const bool occupied = occupied_(ix, iy) != 0;
      f_[iy - iy0] = occupied ? 0.0 : kFar;
      column_occupied = column_occupied || occupied;
    }
    any_occupied = any_occupied || column_occupied;
    if (column_occupied) DistanceTransform1d(f_.data(), h, d_.data(), v_.data(), z_.data());
    for (int iy = y0; iy < y1; ++iy) {
      squared_[(iy - y0) * w + (ix - ix0)] = column_occupied ? d_[iy - iy0] : kFar;
    }
  }
  // Rows, then the capped clearance of the box's cells. Without an occupied
  // cell every row is kFar throughout, and every clearance the same value.
  const double r = limits_.resolution();
  if (!any_occupied) {
    const float far = static_cast<float>(std::min(std::sqrt(kFar) * r, cap_m_));
    for (int iy = y0; iy < y1; ++iy) {
      for (int ix = x0; ix < x1; ++ix) clearance_(ix, iy) = far;
    }
    return;
  }
  for (int iy = y0; iy < y1; ++iy) {
    DistanceTransform1d(&squared_[(iy - y0) * w], w, d_.data(), v_.data(), z_.data());
    for (int ix = x0; ix < x1; ++ix) {
      const double distance = std::sqrt(std::min(d_[ix - ix0], kFar)) * r;
      clearance_(ix, iy) = static_cast<float>(std::min(distance, cap_m_));
    }
  }
}

}  // namespace mjslam::explorer
