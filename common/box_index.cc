#include "common/box_index.h"

#include <algorithm>
#include <cmath>

#include "common/check.h"

namespace mjslam {

BoxIndex::BoxIndex(const std::vector<AlignedBox2>& boxes) : boxes_(boxes) {
  if (boxes_.empty()) {
    starts_.assign(2, 0);
    return;
  }
  // Extent of all boxes and their mean size.
  Eigen::Vector2d lo = boxes_[0].lo;
  Eigen::Vector2d hi = boxes_[0].hi;
  double size_sum = 0.0;
  for (const AlignedBox2& b : boxes_) {
    MJSLAM_CHECK(b.lo.allFinite() && b.hi.allFinite() && (b.lo.array() <= b.hi.array()).all());
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
    size_sum += (b.hi - b.lo).maxCoeff();
  }
  // Cells at least the mean box size, and at most about 4 per box.
  const double n = static_cast<double>(boxes_.size());
  const Eigen::Vector2d extent = (hi - lo).cwiseMax(1e-9);
  cell_m_ = std::max({size_sum / n, std::sqrt(extent.x() * extent.y() / (4.0 * n)), 1e-6});
  width_ = std::max(1, static_cast<int>(std::ceil(extent.x() / cell_m_)));
  height_ = std::max(1, static_cast<int>(std::ceil(extent.y() / cell_m_)));
  origin_ = lo;

  // Count the boxes per cell, then fill (counting sort: compact, ordered).
  starts_.assign(static_cast<std::size_t>(width_) * height_ + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<int> next;
    if (pass == 1) {
      for (std::size_t c = 1; c < starts_.size(); ++c) starts_[c] += starts_[c - 1];
      entries_.resize(starts_.back());
      next.assign(starts_.begin(), starts_.end() - 1);
    }
    for (int k = 0; k < static_cast<int>(boxes_.size()); ++k) {
      int i0, j0, i1, j1;
      CellRange(boxes_[k].lo, boxes_[k].hi, &i0, &j0, &i1, &j1);
      for (int j = j0; j <= j1; ++j) {
        for (int i = i0; i <= i1; ++i) {
          const int c = j * width_ + i;
          if (pass == 0) {
            ++starts_[c + 1];
          } else {
            entries_[next[c]++] = k;
          }
        }
      }
    }
  }
}

void BoxIndex::CellRange(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int* i0, int* j0,
                         int* i1, int* j1) const {
  auto clamp_cell = [](double v, int n) {
    if (!(v > 0.0)) return 0;  // also NaN
    return v >= n - 1 ? n - 1 : static_cast<int>(v);
  };
  *i0 = clamp_cell(std::floor((lo.x() - origin_.x()) / cell_m_), width_);
  *j0 = clamp_cell(std::floor((lo.y() - origin_.y()) / cell_m_), height_);
  *i1 = clamp_cell(std::floor((hi.x() - origin_.x()) / cell_m_), width_);
  *j1 = clamp_cell(std::floor((hi.y() - origin_.y()) / cell_m_), height_);
}

std::vector<int> BoxIndex::Candidates(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const {
  std::vector<int> found;
  if (boxes_.empty()) return found;
  int i0, j0, i1, j1;
  CellRange(lo, hi, &i0, &j0, &i1, &j1);
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const int c = j * width_ + i;
      for (int e = starts_[c]; e < starts_[c + 1]; ++e) {
        const AlignedBox2& b = boxes_[entries_[e]];
        const bool overlaps = b.lo.x() <= hi.x() && lo.x() <= b.hi.x() && b.lo.y() <= hi.y() &&
                              lo.y() <= b.hi.y();
        if (overlaps) found.push_back(entries_[e]);
      }
    }
  }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  return found;
}

}  // namespace mjslam
