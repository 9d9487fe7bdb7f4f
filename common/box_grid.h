#pragma once

#include <algorithm>
#include <vector>

#include <Eigen/Core>

#include "common/grid2.h"

namespace mjslam {

/// An axis-aligned box in the plane (x, y), metres: lo <= hi.
struct Box2 {
  Eigen::Vector2d lo = Eigen::Vector2d::Zero();
  Eigen::Vector2d hi = Eigen::Vector2d::Zero();
};

/// Distance in the plane from p to the box (0 inside it), metres.
double DistanceToBox(const Eigen::Vector2d& p, const Box2& box);

/// A uniform grid of square cells over a set of boxes (a spatial hash): each
/// cell lists the boxes that overlap it, so that a query near a point, over a
/// region, or along a ray traversed cell by cell (common/grid2.h
/// TraverseSegment), looks only at the boxes there. The cost of a query grows
/// with what is near the point, the region or the ray, not with the number
/// of boxes, and tests of n shapes against each other cost about n, not n^2
/// (the uniform grid of Amanatides & Woo, "A fast voxel traversal algorithm
/// for ray tracing", Eurographics 1987). Used by the simulator (a world's
/// static geoms, sim/local_geoms.h) and the ground truth (eval/). Immutable
/// once built; the lists are stored back to back (one index array).
class BoxGrid {
 public:
  /// An empty grid (no boxes, no cells).
  BoxGrid() = default;
  /// Grids `boxes` (ids 0..n-1, in this order; finite, lo <= hi) with cells
  /// of `cell_m` > 0 metres over their union. A box is listed in every cell
  /// its closure touches (a point on a shared side lies in both cells' lists).
  BoxGrid(std::vector<Box2> boxes, double cell_m);
  /// The same with cells chosen from the boxes: at least their mean size and
  /// about 4 cells per box at the most.
  explicit BoxGrid(std::vector<Box2> boxes);

  /// The cells' limits (empty when there are no boxes).
  const GridLimits& limits() const { return limits_; }
  /// Number of boxes.
  int num_boxes() const { return static_cast<int>(boxes_.size()); }
  /// Box `id`, as given.
  const Box2& box(int id) const { return boxes_[id]; }
  /// Ids of the boxes overlapping cell (ix, iy), which must be inside, in
  /// increasing order: [begin, end) into one array.
  const int* CellBegin(int ix, int iy) const { return ids_.data() + start_[limits_.Index(ix, iy)]; }
  const int* CellEnd(int ix, int iy) const {
    return ids_.data() + start_[limits_.Index(ix, iy) + 1];
  }

  /// Calls visit(id) once for each box within `radius_m` (>= 0) of `p`
  /// (DistanceToBox <= radius_m), in increasing id order.
  template <typename Visit>
  void ForEachNear(const Eigen::Vector2d& p, double radius_m, const Visit& visit) const;

  /// The ids of the boxes whose closed extent overlaps the closed box
  /// [lo, hi], increasing and without repeats.
  std::vector<int> Candidates(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const;
  /// Candidates of the single point p.
  std::vector<int> Candidates(const Eigen::Vector2d& p) const { return Candidates(p, p); }

 private:
  GridLimits limits_;
  std::vector<Box2> boxes_;
  // Cell k lists ids_[start_[k] .. start_[k + 1]).
  std::vector<int> start_;
  std::vector<int> ids_;
};

template <typename Visit>
void BoxGrid::ForEachNear(const Eigen::Vector2d& p, double radius_m, const Visit& visit) const {
  if (boxes_.empty()) return;
  const Eigen::Vector2i lo = limits_.CellOf(p - Eigen::Vector2d::Constant(radius_m));
  const Eigen::Vector2i hi = limits_.CellOf(p + Eigen::Vector2d::Constant(radius_m));
  std::vector<int> near;
  for (int iy = std::max(0, lo.y()); iy <= std::min(limits_.height() - 1, hi.y()); ++iy) {
    for (int ix = std::max(0, lo.x()); ix <= std::min(limits_.width() - 1, hi.x()); ++ix) {
      for (const int* id = CellBegin(ix, iy); id != CellEnd(ix, iy); ++id) {
        if (DistanceToBox(p, boxes_[*id]) <= radius_m) near.push_back(*id);
      }
    }
  }
  std::sort(near.begin(), near.end());
  near.erase(std::unique(near.begin(), near.end()), near.end());
  for (const int id : near) visit(id);
}

}  // namespace mjslam
