#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/grid2.h"
#include "common/laser_scan.h"
#include "common/pose2.h"
#include "sim/obstacles.h"

namespace mjslam::app {

/// The distance from each cell centre of `limits` to the nearest of
/// `obstacles` (sim::DistanceToObstacles), exact where it is at most
/// `cutoff_m`; elsewhere some value above `cutoff_m` (infinity when no
/// obstacle is near). Costs about the cells within the cutoff of each
/// obstacle, not cells times obstacles.
Grid2<double> ClearanceGrid(const std::vector<sim::ObstacleFootprint>& obstacles,
                            const GridLimits& limits, double cutoff_m);

/// How much of a world's reachable free area the laser has seen, from the
/// world's true geometry and the true laser poses: the explored fraction of
/// summary.json and trajectory.csv.
///
/// The floor is cut into square cells. A cell is *free* when its centre is
/// more than a few centimetres from every obstacle footprint. The robot can
/// stand where the clearance is at least `robot_radius_m`; the *reachable*
/// cells are those connected (4-neighbour) to the start through such cells,
/// widened by `robot_radius_m` to the free cells beside them (what the body
/// sweeps). A cell is *seen* once a beam crosses it or ends in it.
class TrueCoverage {
 public:
  /// `obstacles`: the world's footprints; `p_W_start`: a point where the
  /// robot stands (its axle centre); `cell_m`, `robot_radius_m` > 0.
  TrueCoverage(const std::vector<sim::ObstacleFootprint>& obstacles,
               const Eigen::Vector2d& p_W_start, double cell_m = 0.1,
               double robot_radius_m = 0.3);

  /// Marks the cells crossed by the beams of `scan` cast from the laser pose
  /// X_WS (no-return beams up to the maximum range).
  void Observe(const Pose2& X_WS, const LaserScan& scan);

  /// Seen reachable cells over reachable cells, in [0, 1].
  double ExploredFraction() const;
  /// Reachable area, m^2.
  double ReachableArea() const;

 private:
  // Linear index of the cell holding p_W; -1 outside the grid.
  int Index(const Eigen::Vector2d& p_W) const;

  GridLimits limits_;
  Grid2<std::uint8_t> reachable_;
  Grid2<std::uint8_t> seen_;
  int num_reachable_ = 0;
  int num_seen_reachable_ = 0;
};

}  // namespace mjslam::app
