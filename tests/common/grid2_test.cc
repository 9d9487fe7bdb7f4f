#include "common/grid2.h"

#include <cmath>
#include <cstdint>
#include <set>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace mjslam {
namespace {

using Cell = std::pair<int, int>;

TEST(GridLimitsTest, CellOfFloorsAndCellCenterIsTheMiddle) {
  const GridLimits limits({-1.0, 2.0}, 0.5, 4, 3);
  EXPECT_EQ(limits.num_cells(), 12);
  EXPECT_EQ(limits.CellOf({-1.0, 2.0}), Eigen::Vector2i(0, 0));
  EXPECT_EQ(limits.CellOf({-0.51, 2.49}), Eigen::Vector2i(0, 0));
  EXPECT_EQ(limits.CellOf({-0.5, 2.5}), Eigen::Vector2i(1, 1));
  // Floor, not truncation, left of and below the origin.
  EXPECT_EQ(limits.CellOf({-1.01, 1.99}), Eigen::Vector2i(-1, -1));
  EXPECT_EQ(limits.CellCenter(0, 0), Eigen::Vector2d(-0.75, 2.25));
  EXPECT_EQ(limits.CellCenter(3, 2), Eigen::Vector2d(0.75, 3.25));
  EXPECT_EQ(limits.far_corner(), Eigen::Vector2d(1.0, 3.5));
  for (int iy = 0; iy < 3; ++iy) {
    for (int ix = 0; ix < 4; ++ix) {
      EXPECT_EQ(limits.CellOf(limits.CellCenter(ix, iy)), Eigen::Vector2i(ix, iy));
    }
  }
}

TEST(GridLimitsTest, ContainsAndIndexRoundTrip) {
  const GridLimits limits({0.0, 0.0}, 1.0, 5, 2);
  EXPECT_TRUE(limits.Contains(0, 0));
  EXPECT_TRUE(limits.Contains(4, 1));
  EXPECT_FALSE(limits.Contains(5, 1));
  EXPECT_FALSE(limits.Contains(4, 2));
  EXPECT_FALSE(limits.Contains(-1, 0));
  EXPECT_FALSE(limits.Contains(Eigen::Vector2i(0, -1)));
  EXPECT_EQ(limits.Index(3, 1), 8);
  for (int i = 0; i < limits.num_cells(); ++i) {
    const Eigen::Vector2i c = limits.CellOfIndex(i);
    EXPECT_EQ(limits.Index(c.x(), c.y()), i);
  }
  EXPECT_EQ(GridLimits().num_cells(), 0);
}

TEST(Grid2Test, CellAndIndexAccessAgree) {
  Grid2<int> grid(GridLimits({0.0, 0.0}, 0.1, 3, 2), 7);
  EXPECT_EQ(grid.cells().size(), 6u);
  EXPECT_EQ(grid(2, 1), 7);
  grid(2, 1) = 4;
  EXPECT_EQ(grid[5], 4);
  grid[1] = 9;
  EXPECT_EQ(grid(1, 0), 9);
  grid.Fill(0);
  EXPECT_EQ(grid(2, 1), 0);
}

// The cells TraverseSegment visits, in order.
std::vector<Cell> Traverse(const GridLimits& limits, const Eigen::Vector2d& a,
                           const Eigen::Vector2d& b) {
  std::vector<Cell> cells;
  TraverseSegment(limits, a, b, [&](int ix, int iy) { cells.emplace_back(ix, iy); });
  return cells;
}

TEST(TraverseSegmentTest, VisitsARowInOrderInBothDirections) {
  const GridLimits limits({0.0, 0.0}, 1.0, 10, 10);
  EXPECT_EQ(Traverse(limits, {0.5, 2.5}, {3.5, 2.5}),
            (std::vector<Cell>{{0, 2}, {1, 2}, {2, 2}, {3, 2}}));
  EXPECT_EQ(Traverse(limits, {3.5, 2.5}, {0.5, 2.5}),
            (std::vector<Cell>{{3, 2}, {2, 2}, {1, 2}, {0, 2}}));
  EXPECT_EQ(Traverse(limits, {4.5, 1.2}, {4.5, 3.9}),
            (std::vector<Cell>{{4, 1}, {4, 2}, {4, 3}}));
  EXPECT_EQ(Traverse(limits, {4.5, 1.2}, {4.6, 1.3}), (std::vector<Cell>{{4, 1}}));
  EXPECT_EQ(Traverse(limits, {4.5, 1.2}, {4.5, 1.2}), (std::vector<Cell>{{4, 1}}));
}

TEST(TraverseSegmentTest, StepsInYFirstThroughAnExactCorner) {
  const GridLimits limits({0.0, 0.0}, 1.0, 4, 4);
  EXPECT_EQ(Traverse(limits, {0.5, 0.5}, {1.5, 1.5}),
            (std::vector<Cell>{{0, 0}, {0, 1}, {1, 1}}));
}

TEST(TraverseSegmentTest, VisitsEveryCellTheSegmentCrossesAsAChainOfNeighbours) {
  const GridLimits limits({-2.0, -3.0}, 0.25, 40, 40);
  const Eigen::Vector2d segments[][2] = {{{-1.9, -2.8}, {6.7, 5.1}},
                                         {{5.3, -0.4}, {-1.1, 2.2}},
                                         {{0.1, 6.2}, {0.35, -2.9}},
                                         {{-1.7, 0.3}, {7.9, 0.2}}};
  for (const auto& s : segments) {
    const std::vector<Cell> cells = Traverse(limits, s[0], s[1]);
    ASSERT_FALSE(cells.empty());
    const Eigen::Vector2i first = limits.CellOf(s[0]);
    const Eigen::Vector2i last = limits.CellOf(s[1]);
    EXPECT_EQ(cells.front(), Cell(first.x(), first.y()));
    EXPECT_EQ(cells.back(), Cell(last.x(), last.y()));
    for (std::size_t k = 1; k < cells.size(); ++k) {
      EXPECT_EQ(std::abs(cells[k].first - cells[k - 1].first) +
                    std::abs(cells[k].second - cells[k - 1].second),
                1);
    }
    // Every point of the segment lies in a visited cell, and nothing else is
    // visited: the visit is the exact set of crossed cells.
    const std::set<Cell> visited(cells.begin(), cells.end());
    EXPECT_EQ(visited.size(), cells.size());
    std::set<Cell> sampled;
    for (int k = 0; k <= 100000; ++k) {
      const Eigen::Vector2i c = limits.CellOf(s[0] + (k / 100000.0) * (s[1] - s[0]));
      sampled.insert({c.x(), c.y()});
    }
    EXPECT_EQ(sampled, visited);
  }
}

// A 5 x 5 grid with a diagonal wall from (0, 4) to (4, 0): the cells below
// it touch the cells above it only at corners.
bool OffDiagonal(int ix, int iy) { return ix + iy != 4; }

TEST(FloodFillTest, FourConnectedStopsAtADiagonalWallEightConnectedCrossesIt) {
  const GridLimits limits({0.0, 0.0}, 1.0, 5, 5);
  Grid2<std::uint8_t> four(limits, 0);
  const std::vector<int> four_cells =
      FloodFill(Eigen::Vector2i(0, 0), Connectivity::kFour, OffDiagonal, &four);
  EXPECT_EQ(four_cells.size(), 10u);  // the triangle ix + iy < 4
  EXPECT_EQ(four(3, 0), 1);
  EXPECT_EQ(four(4, 0), 0);
  EXPECT_EQ(four(4, 4), 0);
  Grid2<std::uint8_t> eight(limits, 0);
  const std::vector<int> eight_cells =
      FloodFill(Eigen::Vector2i(0, 0), Connectivity::kEight, OffDiagonal, &eight);
  EXPECT_EQ(eight_cells.size(), 20u);  // both triangles, not the wall
  EXPECT_EQ(eight(4, 4), 1);
  EXPECT_EQ(eight(2, 2), 0);
}

TEST(FloodFillTest, VisitsBreadthFirstFromTheStartWhateverItsOwnCell) {
  const GridLimits limits({0.0, 0.0}, 1.0, 7, 7);
  Grid2<std::uint8_t> reached(limits, 0);
  const Eigen::Vector2i start(3, 3);
  const std::vector<int> cells = FloodFill(
      start, Connectivity::kFour, [&](int ix, int iy) { return !(ix == 3 && iy == 3); },
      &reached);
  ASSERT_EQ(cells.size(), 49u);
  EXPECT_EQ(cells.front(), limits.Index(3, 3));
  // The first neighbours in the documented order +x, -x, +y, -y.
  EXPECT_EQ(cells[1], limits.Index(4, 3));
  EXPECT_EQ(cells[2], limits.Index(2, 3));
  EXPECT_EQ(cells[3], limits.Index(3, 4));
  EXPECT_EQ(cells[4], limits.Index(3, 2));
  int previous = 0;
  for (const int i : cells) {
    const Eigen::Vector2i c = limits.CellOfIndex(i);
    const int distance = std::abs(c.x() - 3) + std::abs(c.y() - 3);
    EXPECT_GE(distance, previous);
    previous = distance;
  }
}

TEST(FloodFillTest, CellsMarkedBeforeAreWallsSoFillsFindDisjointRegions) {
  const GridLimits limits({0.0, 0.0}, 1.0, 5, 1);
  Grid2<std::uint8_t> reached(limits, 0);
  reached(2, 0) = 1;
  auto open = [](int, int) { return true; };
  EXPECT_EQ(FloodFill(Eigen::Vector2i(0, 0), Connectivity::kEight, open, &reached).size(), 2u);
  EXPECT_EQ(reached(3, 0), 0);
  EXPECT_EQ(FloodFill(Eigen::Vector2i(4, 0), Connectivity::kEight, open, &reached).size(), 2u);
  EXPECT_EQ(reached(3, 0), 1);
}

}  // namespace
}  // namespace mjslam
