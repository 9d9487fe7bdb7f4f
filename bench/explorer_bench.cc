// The cost of the explorer's clearance transform as the explored area grows
// (explorer/clearance_field.h): a laser drives along a 60 m corridor with
// rooms of 4 x 5 m on both sides (0.9 m doors), entering each room; every
// 2 s of driving (the explorer's replan period) the clearance is brought up
// to date incrementally (ClearanceField::Update, what the explorer does),
// recomputed over the whole grid for comparison (ClearanceField::Recompute,
// what it did before), and the path searches of a NavigationMap run on it:
// the whole Dijkstra (what the explorer did before), the explorer's searches
// on demand (A* to a goal 6 m back along the drive, as a replan does, and a
// Dijkstra to a cost of 8 m, the bound a goal choice reaches with a frontier
// a few metres away). Prints, per 10 m of corridor, the CPU time per call of
// each and the cells each settles, side by side, against the explored area
// and the grid's size.
//
//   build/bench/mjslam_explorer_bench

#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <Eigen/Core>

#include "common/angles.h"
#include "common/laser_scan.h"
#include "common/pose2.h"
#include "explorer/clearance_field.h"
#include "explorer/explorer_params.h"
#include "explorer/occupancy_grid.h"
#include "explorer/path_planner.h"
#include "tests/support/walls.h"

namespace mjslam::explorer {
namespace {

using testing::Wall;

constexpr double kCorridorLengthM = 60.0;
constexpr double kCorridorWidthM = 2.2;
constexpr double kRoomWidthM = 4.0;
constexpr double kRoomDepthM = 5.0;
constexpr double kDoorWidthM = 0.9;
// Distance driven per scan (0.4 m/s at 10 Hz), metres; turn per scan, rad.
constexpr double kStepM = 0.04;
constexpr double kTurnStepRad = 0.12;
// Scans between two navigation maps (the 2 s replan period).
constexpr int kScansPerPlan = 20;
// Cost bound of the bounded Dijkstra, metres.
constexpr double kBoundedCostM = 8.0;

// CPU time of this thread, seconds.
double CpuSeconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

// The corridor y in [0, w] along x in [0, L], rooms above and below with a
// door in the middle of each.
std::vector<Wall> Building() {
  std::vector<Wall> walls;
  const double w = kCorridorWidthM;
  const int rooms = static_cast<int>(kCorridorLengthM / kRoomWidthM);
  walls.push_back({{0.0, -kRoomDepthM}, {0.0, w + kRoomDepthM}});
  walls.push_back({{kCorridorLengthM, -kRoomDepthM}, {kCorridorLengthM, w + kRoomDepthM}});
  walls.push_back({{0.0, -kRoomDepthM}, {kCorridorLengthM, -kRoomDepthM}});
  walls.push_back({{0.0, w + kRoomDepthM}, {kCorridorLengthM, w + kRoomDepthM}});
  for (int k = 0; k < rooms; ++k) {
    const double x0 = k * kRoomWidthM;
    const double door = x0 + 0.5 * kRoomWidthM;
    for (const double y : {0.0, w}) {
      walls.push_back({{x0, y}, {door - 0.5 * kDoorWidthM, y}});
      walls.push_back({{door + 0.5 * kDoorWidthM, y}, {x0 + kRoomWidthM, y}});
    }
    if (k > 0) {
      walls.push_back({{x0, -kRoomDepthM}, {x0, 0.0}});
      walls.push_back({{x0, w}, {x0, w + kRoomDepthM}});
    }
  }
  return walls;
}

// The SICK's scan (181 beams over 180 deg, 30 m) from X_WS, exact.
LaserScan Scan(const std::vector<Wall>& walls, const Pose2& X_WS) {
  LaserScan scan;
  scan.angle_min_rad = -0.5 * kPi;
  scan.angle_increment_rad = kPi / 180.0;
  scan.max_range_m = 30.0;
  for (int i = 0; i < 181; ++i) {
    const double th = X_WS.theta + scan.BeamAngle(i);
    const double range =
        testing::CastRay(walls, X_WS.translation(), Eigen::Vector2d(std::cos(th), std::sin(th)));
    const bool echo = range < scan.max_range_m;
    scan.ranges_m.push_back(echo ? range : scan.max_range_m);
    scan.has_return.push_back(echo ? 1 : 0);
  }
  return scan;
}

// The laser's poses: along the corridor's middle, into every room (to its
// middle and back, turning in place), one pose per scan.
std::vector<Pose2> Drive() {
  std::vector<Pose2> poses;
  Pose2 X = Pose2(0.5, 0.5 * kCorridorWidthM, 0.0);
  auto turn_to = [&](double heading) {
    while (std::abs(WrapAngle(heading - X.theta)) > kTurnStepRad) {
      X.theta = WrapAngle(X.theta + std::copysign(kTurnStepRad, WrapAngle(heading - X.theta)));
      poses.push_back(X);
    }
    X.theta = heading;
  };
  auto drive_to = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2d d = p - X.translation();
    turn_to(std::atan2(d.y(), d.x()));
    const int n = static_cast<int>(std::ceil(d.norm() / kStepM));
    const Eigen::Vector2d start = X.translation();
    for (int k = 1; k <= n; ++k) {
      const Eigen::Vector2d q = start + (double(k) / n) * d;
      X.x = q.x();
      X.y = q.y();
      poses.push_back(X);
    }
  };
  const int rooms = static_cast<int>(kCorridorLengthM / kRoomWidthM);
  const double mid = 0.5 * kCorridorWidthM;
  for (int k = 0; k < rooms; ++k) {
    const double door = (k + 0.5) * kRoomWidthM;
    drive_to({door, mid});
    const double side = k % 2 == 0 ? 1.0 : -1.0;
    const double room_y = side > 0 ? kCorridorWidthM + 0.5 * kRoomDepthM : -0.5 * kRoomDepthM;
    drive_to({door, room_y});
    drive_to({door, mid});
  }
  return poses;
}

void Run() {
  const std::vector<Wall> walls = Building();
  const std::vector<Pose2> poses = Drive();
  const ExplorerParams params;
  OccupancyGrid grid(params);
  ClearanceField incremental(ClearanceCapM(params));
  std::printf("Clearance transform per call (every %d scans), CPU ms, same grid, same run\n",
              kScansPerPlan);
  std::printf("%8s %10s %10s %14s %12s %12s %8s %14s %10s %10s %10s %11s %10s\n", "x_m",
              "free_m2", "cells", "incremental_ms", "recomputed", "full_ms", "ratio",
              "dijkstra_ms", "settled", "astar_ms", "settled", "bounded_ms", "settled");
  double incremental_s = 0.0;
  double full_s = 0.0;
  double dijkstra_s = 0.0;
  double astar_s = 0.0;
  double bounded_s = 0.0;
  double dijkstra_cells = 0.0;
  double astar_cells = 0.0;
  double bounded_cells = 0.0;
  double recomputed = 0.0;
  int calls = 0;
  double next_report_x = 10.0;
  for (size_t i = 0; i < poses.size(); ++i) {
    grid.InsertScan(Scan(walls, poses[i]), poses[i]);
    if ((i + 1) % kScansPerPlan != 0) continue;
    double t0 = CpuSeconds();
    recomputed += static_cast<double>(incremental.Update(grid));
    double t1 = CpuSeconds();
    incremental_s += t1 - t0;
    ClearanceField full(ClearanceCapM(params));
    t0 = CpuSeconds();
    full.Recompute(grid);
    t1 = CpuSeconds();
    full_s += t1 - t0;
    t0 = CpuSeconds();
    const NavigationMap map(grid, incremental, params, poses[i].translation());
    t1 = CpuSeconds();
    dijkstra_s += t1 - t0;
    dijkstra_cells += map.settled_cells();
    // A* back to where the laser was 6 m of driving ago (150 scans).
    const size_t back = i >= 150 ? i - 150 : 0;
    t0 = CpuSeconds();
    NavigationMap astar(grid, incremental, params, poses[i].translation(),
                        NavigationMap::Search::kOnDemand);
    astar.SearchTo(grid.CellOf(poses[back].translation()));
    t1 = CpuSeconds();
    astar_s += t1 - t0;
    astar_cells += astar.settled_cells();
    t0 = CpuSeconds();
    NavigationMap bounded(grid, incremental, params, poses[i].translation(),
                          NavigationMap::Search::kOnDemand);
    bounded.ExpandTo(kBoundedCostM);
    t1 = CpuSeconds();
    bounded_s += t1 - t0;
    bounded_cells += bounded.settled_cells();
    ++calls;
    if (poses[i].x >= next_report_x || i + kScansPerPlan >= poses.size()) {
      std::printf("%8.1f %10.0f %10d %14.3f %12.0f %12.3f %8.1f %14.3f %10.0f %10.3f %10.0f %11.3f "
                  "%10.0f\n",
                  poses[i].x, grid.KnownFreeArea(), grid.width() * grid.height(),
                  1e3 * incremental_s / calls, recomputed / calls, 1e3 * full_s / calls,
                  full_s / std::max(incremental_s, 1e-12), 1e3 * dijkstra_s / calls,
                  dijkstra_cells / calls, 1e3 * astar_s / calls, astar_cells / calls,
                  1e3 * bounded_s / calls, bounded_cells / calls);
      std::fflush(stdout);
      incremental_s = full_s = dijkstra_s = recomputed = 0.0;
      astar_s = bounded_s = dijkstra_cells = astar_cells = bounded_cells = 0.0;
      calls = 0;
      next_report_x += 10.0;
    }
  }
}

}  // namespace
}  // namespace mjslam::explorer

int main() {
  mjslam::explorer::Run();
  return 0;
}
