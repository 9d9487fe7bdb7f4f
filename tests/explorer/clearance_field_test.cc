// The incremental clearance field against the whole-grid recomputation and
// a brute-force nearest occupied cell, on grids built from random scans
// (which grow the grid, occupy cells and free some of them again).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/rng.h"
#include "explorer/clearance_field.h"
#include "explorer/occupancy_grid.h"

namespace mjslam::explorer {
namespace {

constexpr double kCapM = 0.9;

// A 181-beam scan over 180 deg with random ranges in [0.3, 6] m; one beam
// in ten without echo.
LaserScan RandomScan(Rng* rng) {
  LaserScan scan;
  const int n = 181;
  scan.angle_min_rad = -0.5 * kPi;
  scan.angle_increment_rad = kPi / (n - 1);
  scan.max_range_m = 30.0;
  for (int i = 0; i < n; ++i) {
    const bool echo = rng->Uniform() > 0.1;
    scan.ranges_m.push_back(echo ? 0.3 + 5.7 * rng->Uniform() : scan.max_range_m);
    scan.has_return.push_back(echo ? 1 : 0);
  }
  return scan;
}

// The capped clearance of every cell by brute force over the occupied cells
// within the cap (a farther one would be capped anyway).
std::vector<float> BruteForce(const OccupancyGrid& grid) {
  const int reach = static_cast<int>(std::ceil(kCapM / grid.resolution()));
  std::vector<float> values;
  for (int iy = 0; iy < grid.height(); ++iy) {
    for (int ix = 0; ix < grid.width(); ++ix) {
      double best = 1e12;
      for (int jy = iy - reach; jy <= iy + reach; ++jy) {
        for (int jx = ix - reach; jx <= ix + reach; ++jx) {
          if (grid.State(jx, jy) != CellState::kOccupied) continue;
          const double dx = jx - ix;
          const double dy = jy - iy;
          best = std::min(best, dx * dx + dy * dy);
        }
      }
      values.push_back(
          static_cast<float>(std::min(std::sqrt(best) * grid.resolution(), kCapM)));
    }
  }
  return values;
}

// Incremental updates after every scan equal the recomputation bit for bit,
// and the recomputation equals the brute force, as the grid grows from a
// few square metres to about 30 x 30 m and cells turn occupied and back.
TEST(ClearanceFieldTest, IncrementalEqualsRecomputation) {
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    Rng rng(seed);
    OccupancyGrid grid{ExplorerParams{}};
    ClearanceField incremental(kCapM);
    Pose2 X_WS(0.0, 0.0, 0.0);
    int changes_seen = 0;
    for (int k = 0; k < 60; ++k) {
      // A random walk that drifts away (the grid grows in every direction).
      X_WS = Pose2(X_WS.x + 1.5 * (rng.Uniform() - 0.5) + (seed == 2 ? -0.2 : 0.2),
                   X_WS.y + 1.5 * (rng.Uniform() - 0.5) + (seed == 3 ? -0.2 : 0.2),
                   2.0 * kPi * rng.Uniform());
      grid.InsertScan(RandomScan(&rng), X_WS);
      incremental.Update(grid);
      ClearanceField full(kCapM);
      full.Recompute(grid);
      ASSERT_EQ(incremental.values().cells(), full.values().cells())
          << "seed " << seed << ", scan " << k;
      if (k == 14) {
        // The brute force is slow: once.
        EXPECT_EQ(full.values().cells(), BruteForce(grid)) << "seed " << seed << ", scan " << k;
      }
      changes_seen = static_cast<int>(grid.occupancy_changes().size());
    }
    std::printf("seed %d: grid %d x %d cells, %d occupancy changes\n", static_cast<int>(seed),
                grid.width(), grid.height(), changes_seen);
    EXPECT_GT(grid.width() * grid.height(), 300 * 300);
  }
}

// An update recomputes only the tiles near the cells that changed: after a
// large grid is built, one short scan in a corner recomputes at most the
// tiles within the cap of that scan, not the grid.
TEST(ClearanceFieldTest, UpdateCostIsLocal) {
  Rng rng(7);
  OccupancyGrid grid{ExplorerParams{}};
  ClearanceField field(kCapM);
  for (int k = 0; k < 40; ++k) {
    grid.InsertScan(RandomScan(&rng), Pose2(0.5 * k, 0.3 * k, 0.7 * k));
    field.Update(grid);
  }
  const size_t total = static_cast<size_t>(grid.width()) * grid.height();
  // Three scans of at most 1 m at the first pose: changes within 1 m of it
  // (an echo on a cell seen free before needs two scans to occupy it).
  LaserScan scan = RandomScan(&rng);
  for (double& r : scan.ranges_m) r = std::min(r, 1.0);
  std::fill(scan.has_return.begin(), scan.has_return.end(), 1);
  for (int k = 0; k < 3; ++k) grid.InsertScan(scan, Pose2(0.0, 0.0, 2.0));
  const size_t recomputed = field.Update(grid);
  // The changed cells lie in a 2 x 2 m box; with the cap (0.9 m) the
  // recomputed tiles of 1.6 m cover at most (2 + 1.8 + 2 x 1.6)^2 m^2.
  const double tile_m = ClearanceField::kTileCells * grid.resolution();
  const double bound_m = 2.0 + 2.0 * kCapM + 2.0 * tile_m;
  std::printf("grid %zu cells, update recomputed %zu cells\n", total, recomputed);
  EXPECT_GT(recomputed, 0u);
  EXPECT_LE(static_cast<double>(recomputed),
            bound_m * bound_m / (grid.resolution() * grid.resolution()));
  EXPECT_LT(recomputed * 10, total);
  // And it is still right.
  ClearanceField full(kCapM);
  full.Recompute(grid);
  EXPECT_EQ(field.values().cells(), full.values().cells());
  // Nothing changed: nothing to recompute.
  EXPECT_EQ(field.Update(grid), 0u);
}

}  // namespace
}  // namespace mjslam::explorer
