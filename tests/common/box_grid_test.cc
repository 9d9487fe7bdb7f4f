// BoxGrid lists each box in every cell its closure touches, and ForEachNear
// and Candidates find exactly the boxes within a radius or overlapping a
// region (against a brute-force search over seeded random boxes and queries).

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "common/rng.h"
#include "common/box_grid.h"

namespace mjslam {
namespace {

Box2 MakeBox(double x0, double y0, double x1, double y1) {
  Box2 box;
  box.lo = Eigen::Vector2d(x0, y0);
  box.hi = Eigen::Vector2d(x1, y1);
  return box;
}

TEST(BoxGridTest, DistanceToBoxIsZeroInsideAndEuclideanOutside) {
  const Box2 box = MakeBox(0, 0, 2, 1);
  EXPECT_EQ(DistanceToBox(Eigen::Vector2d(1, 0.5), box), 0.0);
  EXPECT_EQ(DistanceToBox(Eigen::Vector2d(2, 1), box), 0.0);
  EXPECT_DOUBLE_EQ(DistanceToBox(Eigen::Vector2d(3, 0.5), box), 1.0);
  EXPECT_DOUBLE_EQ(DistanceToBox(Eigen::Vector2d(5, 5), box), 5.0);
  EXPECT_DOUBLE_EQ(DistanceToBox(Eigen::Vector2d(-1, -1), box), std::sqrt(2.0));
}

TEST(BoxGridTest, ListsABoxInEveryCellItsClosureTouches) {
  // A box whose sides lie on cell boundaries (cells of 1 m from x = -1).
  const BoxGrid grid({MakeBox(0, 0, 2, 1), MakeBox(0.2, 0.2, 0.3, 0.3)}, 1.0);
  const GridLimits& limits = grid.limits();
  for (int iy = 0; iy < limits.height(); ++iy) {
    for (int ix = 0; ix < limits.width(); ++ix) {
      const Eigen::Vector2d lo = limits.CellCenter(ix, iy) - Eigen::Vector2d(0.5, 0.5);
      const Eigen::Vector2d hi = lo + Eigen::Vector2d(1, 1);
      for (int id = 0; id < grid.num_boxes(); ++id) {
        const Box2& box = grid.box(id);
        const bool touches = box.lo.x() <= hi.x() && lo.x() <= box.hi.x() &&
                             box.lo.y() <= hi.y() && lo.y() <= box.hi.y();
        const std::set<int> listed(grid.CellBegin(ix, iy), grid.CellEnd(ix, iy));
        EXPECT_EQ(listed.count(id) == 1, touches) << ix << " " << iy << " box " << id;
      }
    }
  }
}

TEST(BoxGridTest, ForEachNearFindsExactlyTheBoxesWithinTheRadius) {
  // Seed 7: 300 boxes of up to 6 x 6 m in 60 x 40 m, 200 queries.
  Rng rng(7);
  std::vector<Box2> boxes;
  for (int k = 0; k < 300; ++k) {
    const double x = rng.Uniform() * 60 - 30;
    const double y = rng.Uniform() * 40 - 20;
    boxes.push_back(MakeBox(x, y, x + rng.Uniform() * 6, y + rng.Uniform() * 6));
  }
  const BoxGrid grid(boxes, 1.0);
  for (int q = 0; q < 200; ++q) {
    const Eigen::Vector2d p(rng.Uniform() * 70 - 35, rng.Uniform() * 50 - 25);
    const double radius = rng.Uniform() * 3;
    std::vector<int> expected;
    for (int id = 0; id < static_cast<int>(boxes.size()); ++id) {
      if (DistanceToBox(p, boxes[id]) <= radius) expected.push_back(id);
    }
    std::vector<int> found;
    grid.ForEachNear(p, radius, [&](int id) { found.push_back(id); });
    EXPECT_EQ(found, expected) << "query " << q;
  }
}

TEST(BoxGridTest, AnEmptyGridHasNoCellsAndFindsNothing) {
  const BoxGrid grid({}, 1.0);
  EXPECT_EQ(grid.limits().num_cells(), 0);
  int found = 0;
  grid.ForEachNear(Eigen::Vector2d(0, 0), 10.0, [&](int) { ++found; });
  EXPECT_EQ(found, 0);
}

bool Overlaps(const Box2& b, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  return b.lo.x() <= hi.x() && lo.x() <= b.hi.x() && b.lo.y() <= hi.y() && lo.y() <= b.hi.y();
}

TEST(BoxGridTest, CandidatesAreExactlyTheOverlappingBoxes) {
  std::mt19937_64 rng(7);  // seed printed by the failure message's trace
  std::uniform_real_distribution<double> position(-50.0, 50.0);
  std::uniform_real_distribution<double> size(0.0, 3.0);
  for (const int num : {0, 1, 10, 2000}) {
    SCOPED_TRACE("seed 7, boxes " + std::to_string(num));
    std::vector<Box2> boxes;
    for (int k = 0; k < num; ++k) {
      const Eigen::Vector2d lo(position(rng), position(rng));
      // Some long walls and some points among small boxes.
      const double long_side = k % 50 == 0 ? 40.0 : size(rng);
      boxes.push_back({lo, lo + Eigen::Vector2d(long_side, k % 7 == 0 ? 0.0 : size(rng))});
    }
    // Cells chosen from the boxes, and 1 m cells.
    for (const BoxGrid& grid : {BoxGrid(boxes), BoxGrid(boxes, 1.0)}) {
      for (int q = 0; q < 300; ++q) {
        // Queries inside, across and outside the boxes' extent, and points.
        const Eigen::Vector2d lo(1.3 * position(rng), 1.3 * position(rng));
        const Eigen::Vector2d hi = q % 3 == 0 ? lo : Eigen::Vector2d(lo + Eigen::Vector2d(
                                                     4.0 * size(rng), 4.0 * size(rng)));
        std::vector<int> expected;
        for (int k = 0; k < num; ++k) {
          if (Overlaps(boxes[k], lo, hi)) expected.push_back(k);
        }
        ASSERT_EQ(grid.Candidates(lo, hi), expected) << "query " << q;
      }
      // A box's own corners find it.
      for (int k = 0; k < num; ++k) {
        const std::vector<int> found = grid.Candidates(boxes[k].hi);
        ASSERT_TRUE(std::binary_search(found.begin(), found.end(), k)) << k;
      }
    }
  }
}

}  // namespace
}  // namespace mjslam
