#include <cmath>

#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "explorer/occupancy_grid.h"
#include "tests/support/kinematic_sim.h"

namespace mjslam::explorer {
namespace {

// A scan of `n` beams over 180 deg, every beam with the same range.
LaserScan UniformScan(int n, double range, bool echo, double max_range) {
  LaserScan scan;
  scan.angle_min_rad = -0.5 * kPi;
  scan.angle_increment_rad = kPi / (n - 1);
  scan.max_range_m = max_range;
  scan.ranges_m.assign(n, echo ? range : max_range);
  scan.has_return.assign(n, echo ? 1 : 0);
  return scan;
}

TEST(OccupancyGridTest, EchoIsOccupiedAndBeamIsFree) {
  OccupancyGrid grid{ExplorerParams{}};
  LaserScan scan = UniformScan(181, 2.0, true, 30.0);
  grid.InsertScan(scan, Pose2(1.0, 1.0, 0.0));
  // Straight ahead: free up to the echo at 2 m, occupied there, unknown behind.
  EXPECT_EQ(grid.StateAt({2.0, 1.0}), CellState::kFree);
  EXPECT_EQ(grid.StateAt({2.9, 1.0}), CellState::kFree);
  EXPECT_EQ(grid.StateAt({3.0, 1.0}), CellState::kOccupied);
  EXPECT_EQ(grid.StateAt({3.3, 1.0}), CellState::kUnknown);
  // Behind the laser (it sees 180 deg only): unknown.
  EXPECT_EQ(grid.StateAt({0.5, 1.0}), CellState::kUnknown);
  // Between two beams at 1.9 m (beams 1 deg apart, 3.3 cm there): free too.
  const double th = 0.5 * DegToRad(1.0) + DegToRad(30.0);
  EXPECT_EQ(grid.StateAt(Eigen::Vector2d(1.0, 1.0) + 1.9 * Eigen::Vector2d(std::cos(th),
                                                                           std::sin(th))),
            CellState::kFree);
}

TEST(OccupancyGridTest, NoReturnClearsOnlyUpToItsRange) {
  ExplorerParams params;
  params.no_return_free_range_m = 3.0;
  OccupancyGrid grid(params);
  grid.InsertScan(UniformScan(181, 0.0, false, 30.0), Pose2(0.0, 0.0, 0.0));
  EXPECT_EQ(grid.StateAt({2.8, 0.0}), CellState::kFree);
  EXPECT_EQ(grid.StateAt({3.2, 0.0}), CellState::kUnknown);
  EXPECT_EQ(grid.StateAt({10.0, 0.0}), CellState::kUnknown);
  // No occupied cell anywhere.
  for (int iy = 0; iy < grid.height(); ++iy) {
    for (int ix = 0; ix < grid.width(); ++ix) {
      ASSERT_NE(grid.State(ix, iy), CellState::kOccupied);
    }
  }
}

TEST(OccupancyGridTest, FarEchoOnlyClearsUpToInsertRange) {
  ExplorerParams params;
  params.max_insert_range_m = 5.0;
  OccupancyGrid grid(params);
  grid.InsertScan(UniformScan(181, 7.0, true, 30.0), Pose2(0.0, 0.0, 0.0));
  EXPECT_EQ(grid.StateAt({4.8, 0.0}), CellState::kFree);
  EXPECT_EQ(grid.StateAt({7.0, 0.0}), CellState::kUnknown);
}

TEST(OccupancyGridTest, RepeatedMissesOverrideOneHit) {
  OccupancyGrid grid{ExplorerParams{}};
  // One scan sees a wall at 2 m; later scans see through it to 4 m.
  grid.InsertScan(UniformScan(181, 2.0, true, 30.0), Pose2(0.0, 0.0, 0.0));
  ASSERT_EQ(grid.StateAt({2.0, 0.0}), CellState::kOccupied);
  for (int k = 0; k < 4; ++k) {
    grid.InsertScan(UniformScan(181, 4.0, true, 30.0), Pose2(0.0, 0.0, 0.0));
  }
  EXPECT_EQ(grid.StateAt({2.0, 0.0}), CellState::kFree);
  EXPECT_EQ(grid.StateAt({4.0, 0.0}), CellState::kOccupied);
}

TEST(OccupancyGridTest, GrowsKeepingCellsInPlace) {
  OccupancyGrid grid{ExplorerParams{}};
  grid.InsertScan(UniformScan(181, 2.0, true, 30.0), Pose2(0.0, 0.0, 0.0));
  const int width = grid.width();
  // A scan far away grows the grid; the first scan's cells keep their state.
  grid.InsertScan(UniformScan(181, 2.0, true, 30.0), Pose2(-20.0, 5.0, kPi));
  EXPECT_GT(grid.width(), width);
  EXPECT_EQ(grid.StateAt({2.0, 0.0}), CellState::kOccupied);
  EXPECT_EQ(grid.StateAt({1.0, 0.0}), CellState::kFree);
  EXPECT_EQ(grid.StateAt({-22.0, 5.0}), CellState::kOccupied);
}

TEST(OccupancyGridTest, ScanFromAPoseFarOutsideTheWorldIsAnErrorNotACrash) {
  // A diverged estimate 1e9 m away, or NaN: the grid would need more cells
  // than memory holds; it says so, and keeps what it has.
  OccupancyGrid grid{ExplorerParams{}};
  grid.InsertScan(UniformScan(181, 2.0, true, 30.0), Pose2(0.0, 0.0, 0.0));
  const int width = grid.width();
  try {
    grid.InsertScan(UniformScan(181, 2.0, true, 30.0), Pose2(1e9, 0.0, 0.0));
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("has left the world"), std::string::npos) << e.what();
  }
  EXPECT_THROW(grid.InsertScan(UniformScan(181, 2.0, true, 30.0),
                               Pose2(std::nan(""), 0.0, 0.0)),
               std::runtime_error);
  EXPECT_EQ(grid.width(), width);
  EXPECT_EQ(grid.StateAt({2.0, 0.0}), CellState::kOccupied);
}

TEST(OccupancyGridTest, RoomWallsAreOccupiedAndInsideFree) {
  // Exact scans from the middle of a 6 x 4 m room, four headings.
  const std::vector<testing::Wall> walls = testing::Box(0.0, 0.0, 6.0, 4.0);
  OccupancyGrid grid{ExplorerParams{}};
  testing::KinematicSim::Config config;
  for (int k = 0; k < 4; ++k) {
    testing::KinematicSim sim(walls, Pose2(3.0, 2.0, k * 0.5 * kPi), config);
    grid.InsertScan(sim.Scan(0.0), sim.X_WR() * config.X_RS);
  }
  int free_inside = 0;
  int total_inside = 0;
  for (double x = 0.2; x < 5.8; x += 0.1) {
    for (double y = 0.2; y < 3.8; y += 0.1) {
      ++total_inside;
      free_inside += grid.StateAt({x, y}) == CellState::kFree;
    }
  }
  EXPECT_EQ(free_inside, total_inside);
  // Points just inside each wall hit a cell that is occupied (walls lie on
  // cell borders: the echo cell is on one side or the other).
  for (double x = 0.5; x < 5.6; x += 0.5) {
    EXPECT_TRUE(grid.StateAt({x, 3.99}) == CellState::kOccupied ||
                grid.StateAt({x, 4.01}) == CellState::kOccupied)
        << x;
  }
}

}  // namespace
}  // namespace mjslam::explorer
