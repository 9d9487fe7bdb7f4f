// The grid of boxes answers exactly what a scan of every box would.
#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "common/box_index.h"

namespace mjslam {
namespace {

bool Overlaps(const AlignedBox2& b, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  return b.lo.x() <= hi.x() && lo.x() <= b.hi.x() && b.lo.y() <= hi.y() && lo.y() <= b.hi.y();
}

TEST(BoxIndexTest, CandidatesAreExactlyTheOverlappingBoxes) {
  std::mt19937_64 rng(7);  // seed printed by the failure message's trace
  std::uniform_real_distribution<double> position(-50.0, 50.0);
  std::uniform_real_distribution<double> size(0.0, 3.0);
  for (const int num : {0, 1, 10, 2000}) {
    SCOPED_TRACE("seed 7, boxes " + std::to_string(num));
    std::vector<AlignedBox2> boxes;
    for (int k = 0; k < num; ++k) {
      const Eigen::Vector2d lo(position(rng), position(rng));
      // Some long walls and some points among small boxes.
      const double long_side = k % 50 == 0 ? 40.0 : size(rng);
      boxes.push_back({lo, lo + Eigen::Vector2d(long_side, k % 7 == 0 ? 0.0 : size(rng))});
    }
    const BoxIndex index(boxes);
    for (int q = 0; q < 300; ++q) {
      // Queries inside, across and outside the boxes' extent, and points.
      const Eigen::Vector2d lo(1.3 * position(rng), 1.3 * position(rng));
      const Eigen::Vector2d hi = q % 3 == 0 ? lo : Eigen::Vector2d(lo + Eigen::Vector2d(
                                                   4.0 * size(rng), 4.0 * size(rng)));
      std::vector<int> expected;
      for (int k = 0; k < num; ++k) {
        if (Overlaps(boxes[k], lo, hi)) expected.push_back(k);
      }
      ASSERT_EQ(index.Candidates(lo, hi), expected) << "query " << q;
    }
    // A box's own corners find it.
    for (int k = 0; k < num; ++k) {
      const std::vector<int> found = index.Candidates(boxes[k].hi);
      ASSERT_TRUE(std::binary_search(found.begin(), found.end(), k)) << k;
    }
  }
}

}  // namespace
}  // namespace mjslam
