#include "common/box_grid.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "common/check.h"

namespace mjslam {
namespace {

// Cells at least the boxes' mean size, and at most about 4 per box (1 m
// without boxes).
double CellSizeFor(const std::vector<Box2>& boxes) {
  if (boxes.empty()) return 1.0;
  Eigen::Vector2d lo = boxes.front().lo;
  Eigen::Vector2d hi = boxes.front().hi;
  double size_sum = 0.0;
  for (const Box2& box : boxes) {
    lo = lo.cwiseMin(box.lo);
    hi = hi.cwiseMax(box.hi);
    size_sum += (box.hi - box.lo).maxCoeff();
  }
  const double n = static_cast<double>(boxes.size());
  const Eigen::Vector2d extent = (hi - lo).cwiseMax(1e-9);
  return std::max({size_sum / n, std::sqrt(extent.x() * extent.y() / (4.0 * n)), 1e-6});
}

}  // namespace

double DistanceToBox(const Eigen::Vector2d& p, const Box2& box) {
  const double dx = std::max({box.lo.x() - p.x(), 0.0, p.x() - box.hi.x()});
  const double dy = std::max({box.lo.y() - p.y(), 0.0, p.y() - box.hi.y()});
  return std::hypot(dx, dy);
}

BoxGrid::BoxGrid(std::vector<Box2> boxes, double cell_m) : boxes_(std::move(boxes)) {
  MJSLAM_CHECK(cell_m > 0.0);
  if (boxes_.empty()) return;
  Eigen::Vector2d lo = boxes_.front().lo;
  Eigen::Vector2d hi = boxes_.front().hi;
  for (const Box2& box : boxes_) {
    MJSLAM_CHECK(box.lo.allFinite() && box.hi.allFinite() && box.lo.x() <= box.hi.x() &&
                 box.lo.y() <= box.hi.y());
    lo = lo.cwiseMin(box.lo);
    hi = hi.cwiseMax(box.hi);
  }
  // One cell of border on each side, so that every box's closure lies
  // strictly inside the grid.
  const Eigen::Vector2d origin = lo - Eigen::Vector2d::Constant(cell_m);
  limits_ = GridLimits(origin, cell_m,
                       static_cast<int>(std::floor((hi.x() - origin.x()) / cell_m)) + 2,
                       static_cast<int>(std::floor((hi.y() - origin.y()) / cell_m)) + 2);

  // Each box's range of cells, then the lists by counting (ids stay in
  // increasing order within a cell).
  std::vector<std::pair<Eigen::Vector2i, Eigen::Vector2i>> ranges;
  ranges.reserve(boxes_.size());
  std::vector<int> count(static_cast<std::size_t>(limits_.num_cells()) + 1, 0);
  for (const Box2& box : boxes_) {
    // The closure [lo, hi] touches the cells from floor(lo) to floor(hi),
    // and also the cell below a side that lies exactly on a cell boundary.
    Eigen::Vector2i first = limits_.CellOf(box.lo);
    const Eigen::Vector2i last = limits_.CellOf(box.hi);
    for (int axis = 0; axis < 2; ++axis) {
      const double boundary = origin[axis] + cell_m * first[axis];
      if (box.lo[axis] <= boundary) --first[axis];
    }
    first = first.cwiseMax(0);
    ranges.emplace_back(first, last);
    for (int iy = first.y(); iy <= last.y(); ++iy) {
      for (int ix = first.x(); ix <= last.x(); ++ix) ++count[limits_.Index(ix, iy) + 1];
    }
  }
  start_.assign(count.size(), 0);
  for (std::size_t k = 1; k < count.size(); ++k) start_[k] = start_[k - 1] + count[k];
  ids_.assign(static_cast<std::size_t>(start_.back()), -1);
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  for (int id = 0; id < num_boxes(); ++id) {
    const auto& [first, last] = ranges[id];
    for (int iy = first.y(); iy <= last.y(); ++iy) {
      for (int ix = first.x(); ix <= last.x(); ++ix) ids_[fill[limits_.Index(ix, iy)]++] = id;
    }
  }
}

BoxGrid::BoxGrid(std::vector<Box2> boxes) : BoxGrid(boxes, CellSizeFor(boxes)) {}

std::vector<int> BoxGrid::Candidates(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const {
  std::vector<int> found;
  if (boxes_.empty()) return found;
  // The cells of lo and hi (as CellOf), clamped to the grid before the cast
  // to int, so that far or NaN queries stay in range.
  auto cell = [&](double v, double origin, int n) {
    const double q = std::floor((v - origin) / limits_.resolution());
    if (!(q > 0.0)) return 0;  // also NaN
    return q >= n - 1 ? n - 1 : static_cast<int>(q);
  };
  const Eigen::Vector2d& origin = limits_.origin();
  const int ix0 = cell(lo.x(), origin.x(), limits_.width());
  const int iy0 = cell(lo.y(), origin.y(), limits_.height());
  const int ix1 = cell(hi.x(), origin.x(), limits_.width());
  const int iy1 = cell(hi.y(), origin.y(), limits_.height());
  for (int iy = iy0; iy <= iy1; ++iy) {
    for (int ix = ix0; ix <= ix1; ++ix) {
      for (const int* id = CellBegin(ix, iy); id != CellEnd(ix, iy); ++id) {
        const Box2& b = boxes_[*id];
        const bool overlaps = b.lo.x() <= hi.x() && lo.x() <= b.hi.x() && b.lo.y() <= hi.y() &&
                              lo.y() <= b.hi.y();
        if (overlaps) found.push_back(*id);
      }
    }
  }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  return found;
}

}  // namespace mjslam
