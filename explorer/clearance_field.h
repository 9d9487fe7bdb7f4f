#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/grid2.h"
#include "explorer/occupancy_grid.h"

namespace mjslam::explorer {

/// The clearance of every cell of an occupancy grid: the Euclidean distance
/// from its centre to the centre of the nearest occupied cell, capped at
/// `cap_m`, metres (the exact distance transform of Felzenszwalb and
/// Huttenlocher, "Distance Transforms of Sampled Functions", 2012).
///
/// Kept up to date incrementally: `Update` reads the grid's log of occupancy
/// changes and recomputes only the tiles of `kTileCells` x `kTileCells`
/// cells within the cap of a changed cell (and, when the grid has grown, the
/// new cells within the cap of the old ones), each from the occupied cells
/// within the cap of the tile. Because the clearance is capped, a cell's value
/// depends only on the occupied cells within `cap_m` of it, so the result is
/// bit for bit that of a recomputation over the whole grid (`Recompute`),
/// while the cost of an update depends on what changed, not on the size of
/// the grid. (Departure from the paper's planner, which has no cap: nothing
/// in the explorer reads a clearance beyond its preferred clearance.)
class ClearanceField {
 public:
  /// Side of a tile, cells.
  static constexpr int kTileCells = 32;

  /// `cap_m` > 0: clearances larger than this are stored as `cap_m`.
  explicit ClearanceField(double cap_m);

  /// Brings the field up to date with `grid`, which must be the grid of every
  /// earlier Update and Recompute (its change log is read from where the last
  /// call stopped). Returns the number of cells recomputed.
  std::size_t Update(const OccupancyGrid& grid);
  /// Recomputes every cell of `grid` (the reference for Update; also the way
  /// to start from a grid that already holds scans). Returns the number of
  /// cells recomputed.
  std::size_t Recompute(const OccupancyGrid& grid);

  /// Clearance of cell (ix, iy) of the grid's limits, metres; 0 outside.
  double Clearance(int ix, int iy) const {
    return limits_.Contains(ix, iy) ? clearance_(ix, iy) : 0.0;
  }
  /// The cap, metres.
  double cap_m() const { return cap_m_; }
  /// The limits of the grid at the last Update or Recompute.
  const GridLimits& limits() const { return limits_; }
  /// Every cell's clearance, metres.
  const Grid2<float>& values() const { return clearance_; }

 private:
  // Takes the grid's limits: copies the cells kept, sets new cells to
  // not occupied with the cap, and marks the new cells within the cap of
  // the old ones for recomputation.
  void Resize(const OccupancyGrid& grid);
  // Marks the tiles overlapping the cell box [x0, x1] x [y0, y1] (clipped).
  void MarkDirty(int x0, int y0, int x1, int y1);
  // Recomputes the dirty tiles (consecutive tiles of a row together) and
  // clears their marks; returns the number of cells recomputed.
  std::size_t RecomputeDirty();
  // Recomputes the cells of [x0, x1) x [y0, y1) from the occupied cells
  // within the cap of that box.
  void RecomputeBox(int x0, int y0, int x1, int y1);

  double cap_m_;
  // The cap in whole cells (rounded up): the reach of an occupied cell.
  int cap_cells_;
  GridLimits limits_;
  Eigen::Vector2i lattice_origin_ = Eigen::Vector2i::Zero();
  // Per cell: occupied (1) as of the last change read; clearance, metres.
  Grid2<std::uint8_t> occupied_;
  Grid2<float> clearance_;
  // Per tile (row by row): whether it must be recomputed.
  int tiles_x_ = 0;
  int tiles_y_ = 0;
  std::vector<std::uint8_t> dirty_;
  // How many entries of the grid's change log have been read.
  std::size_t changes_read_ = 0;
  // Scratch space of RecomputeBox.
  std::vector<double> squared_;
  std::vector<double> f_;
  std::vector<double> d_;
  std::vector<int> v_;
  std::vector<double> z_;
};

}  // namespace mjslam::explorer
