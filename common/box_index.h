#pragma once

#include <vector>

#include <Eigen/Core>

namespace mjslam {

/// An axis-aligned box in the plane: lower and upper corners, metres.
struct AlignedBox2 {
  Eigen::Vector2d lo = Eigen::Vector2d::Zero();
  Eigen::Vector2d hi = Eigen::Vector2d::Zero();
};

/// A uniform grid over axis-aligned boxes (a spatial hash): answers "which
/// boxes may touch this region" in time proportional to the boxes near it,
/// so that tests of n shapes against each other cost about n, not n^2. The
/// grid has at most about 4 cells per box (at least the mean box size),
/// stored compactly (one index array per grid, no per-cell vectors).
class BoxIndex {
 public:
  /// Indexes `boxes` (finite, lo <= hi); a box's index is its position.
  explicit BoxIndex(const std::vector<AlignedBox2>& boxes);

  /// The indices of the boxes whose closed extent overlaps the closed box
  /// [lo, hi], increasing and without repeats.
  std::vector<int> Candidates(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const;

  /// Candidates of the single point p.
  std::vector<int> Candidates(const Eigen::Vector2d& p) const { return Candidates(p, p); }

 private:
  // Cell range [i0, i1] x [j0, j1] covering [lo, hi], clamped to the grid.
  void CellRange(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int* i0, int* j0,
                 int* i1, int* j1) const;

  std::vector<AlignedBox2> boxes_;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  double cell_m_ = 1.0;
  int width_ = 1;
  int height_ = 1;
  // Boxes of cell c: entries_[starts_[c] .. starts_[c + 1]).
  std::vector<int> starts_;
  std::vector<int> entries_;
};

}  // namespace mjslam
