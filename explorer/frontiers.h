#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "common/laser_scan.h"
#include "common/pose2.h"
#include "explorer/explorer_params.h"
#include "explorer/occupancy_grid.h"

namespace mjslam::explorer {

/// Local frontier points of one scan taken with the laser at `X_WS`, in W
/// (the paper's "local frontier points", docs/method.md, "The explorer"):
/// - an opening between two consecutive echoes at least `min_opening_m`
///   apart (a door seen past its jamb, a corridor branching off): the point
///   is the middle of the gap, moved `frontier_standoff_m` toward the laser;
/// - a run of consecutive open beams (no echo, or an echo beyond
///   `max_insert_range_m`) whose arc at `no_return_free_range_m` is at least
///   `min_opening_m` wide: the point is on the run's middle beam,
///   `frontier_standoff_m` short of that range.
/// Whether a point is worth visiting (not explored yet, reachable, away from
/// walls) is decided later against the grid (InformationGain, NavigationMap).
std::vector<Eigen::Vector2d> LocalFrontierPoints(const LaserScan& scan, const Pose2& X_WS,
                                                 const ExplorerParams& params);

/// Global frontier points of the grid: the free cells next to an unknown
/// cell (4-neighbours), grouped into 8-connected clusters; clusters smaller
/// than `min_frontier_cells` are dropped, larger ones are cut into pieces of
/// about one metre and each piece gives its cell nearest to its centroid.
/// In order of the clusters' first cell (row-major), deterministic.
std::vector<Eigen::Vector2d> GlobalFrontierPoints(const OccupancyGrid& grid,
                                                  const ExplorerParams& params);

/// Information gain of standing at `p_W`: the area of the unknown cells
/// within `radius_m` that rays from `p_W` reach before an occupied cell (a
/// cell next to an occupied one also stops a ray, so that a ray does not slip
/// through a one-cell hole in a wall), m^2.
double InformationGain(const OccupancyGrid& grid, const Eigen::Vector2d& p_W, double radius_m);

/// Whether InformationGain(grid, p_W, radius_m) >= `min_gain_m2`, decided
/// the same way for every input, but returning as soon as the unknown area
/// counted so far reaches `min_gain_m2` (a goal's frontier that still has
/// gain, the common case, costs a fraction of the full count).
bool HasInformationGain(const OccupancyGrid& grid, const Eigen::Vector2d& p_W, double radius_m,
                        double min_gain_m2);

/// InformationGain with memory, for points scored again and again (the
/// global frontier points, at every choice of a goal): a point's gain is
/// kept and given again while no cell its count reads has changed state
/// since (OccupancyGrid::state_changes), the same value, bit for bit, as
/// InformationGain. Made for one grid and one radius.
class GainCache {
 public:
  /// InformationGain(grid, p_W, radius_m); `grid` and `radius_m` the same
  /// at every call.
  double Gain(const OccupancyGrid& grid, const Eigen::Vector2d& p_W, double radius_m);

 private:
  // A point's gain, the lattice box of the cells its count reads, and how
  // many of the grid's state changes the entry has been checked against.
  struct Entry {
    double gain_m2;
    OccupancyGrid::LatticeBox reads;
    std::size_t changes_checked;
  };
  // Points by the bits of their coordinates.
  struct PointHash {
    std::size_t operator()(const std::pair<std::uint64_t, std::uint64_t>& key) const {
      return std::hash<std::uint64_t>()(key.first * 0x9E3779B97F4A7C15ULL ^ key.second);
    }
  };
  std::unordered_map<std::pair<std::uint64_t, std::uint64_t>, Entry, PointHash> entries_;
  double radius_m_ = -1.0;
};

}  // namespace mjslam::explorer
