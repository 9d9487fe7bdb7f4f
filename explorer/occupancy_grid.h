#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/grid2.h"
#include "common/laser_scan.h"
#include "common/pose2.h"
#include "explorer/explorer_params.h"

namespace mjslam::explorer {

/// State of one cell as the planner sees it.
enum class CellState : std::uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };

/// A 2-D occupancy grid in log-odds (Probabilistic Robotics, ch. 9, the
/// inverse sensor model of a range finder), in the world frame W. It starts
/// empty and grows (in chunks of whole cells, keeping existing cells where they
/// are) to cover every scan inserted, so no world bound is needed.
///
/// Departures from the textbook model: each cell is updated at most once per
/// scan; a beam's free part stops short of its echo by 0.7 cell across the
/// surface (up to 0.3 m along a grazing beam), so that grazing beams do not
/// erase the wall they run along; the free space between two consecutive beams is filled up to the
/// shorter of the two ranges (sub-rays), so that far-away free space has no
/// unknown holes between diverging beams; echoes beyond `max_insert_range_m`
/// only clear free space up to that range, and no-return beams clear free
/// space up to `no_return_free_range_m` only (the SICK reports no echo for
/// dark or distant surfaces, so "nothing up to 30 m" is not trusted).
class OccupancyGrid {
 public:
  /// The grid of the explorer's settings under "Occupancy grid" in
  /// `params` (grid_resolution_m, the ranges, the log-odds and thresholds),
  /// which must be valid (ExplorerParams::ValidateOrThrow checks them).
  explicit OccupancyGrid(const ExplorerParams& params);

  /// Inserts one scan taken with the laser frame S at `X_WS`.
  void InsertScan(const LaserScan& scan, const Pose2& X_WS);

  /// Marks every cell whose centre lies in the rectangle [x0, x1] x [-hw, hw]
  /// of the frame at `X_WB` as free (once, with `log_odds_miss`): the robot's
  /// own body stands there, so it is not an obstacle.
  void MarkRectangleFree(const Pose2& X_WB, double x0_m, double x1_m, double half_width_m);

  /// The grid's limits (no cells before the first insertion).
  const GridLimits& limits() const { return limits_; }
  /// Cell size, metres.
  double resolution() const { return params_.grid_resolution_m; }
  /// Grid size in cells (0 before the first insertion).
  int width() const { return limits_.width(); }
  int height() const { return limits_.height(); }
  /// World coordinates of the corner of cell (0, 0), metres.
  Eigen::Vector2d origin() const { return limits_.origin(); }

  /// True when (ix, iy) lies inside the grid.
  bool Contains(int ix, int iy) const { return limits_.Contains(ix, iy); }
  /// Linear index of cell (ix, iy), which must be inside.
  int Index(int ix, int iy) const { return limits_.Index(ix, iy); }
  /// Cell containing the world point `p_W` (may be outside the grid).
  Eigen::Vector2i CellOf(const Eigen::Vector2d& p_W) const { return limits_.CellOf(p_W); }
  /// World coordinates of the centre of cell (ix, iy).
  Eigen::Vector2d CellCenter(int ix, int iy) const { return limits_.CellCenter(ix, iy); }

  /// Log-odds of a cell; 0 (unknown) outside the grid.
  double LogOdds(int ix, int iy) const;
  /// State of a cell from the thresholds; unknown outside the grid.
  CellState State(int ix, int iy) const {
    return Contains(ix, iy) ? StateOfLogOdds(log_odds_[Index(ix, iy)]) : CellState::kUnknown;
  }
  /// State of the cell containing `p_W`.
  CellState StateAt(const Eigen::Vector2d& p_W) const;

  /// Area of the known-free cells, m^2 (for reports and tests).
  double KnownFreeArea() const;

  /// Lattice index of cell (0, 0): cell (ix, iy) is lattice cell
  /// (ix, iy) + lattice_origin(). Lattice indices do not change when the grid
  /// grows (the origin moves by whole cells).
  const Eigen::Vector2i& lattice_origin() const { return lattice_origin_; }
  /// Every change of a cell into or out of the occupied state since the
  /// grid was made, as lattice indices in the order they happened (a cell
  /// may appear more than once). Append-only: a reader remembers how many
  /// entries it has read (ClearanceField does).
  const std::vector<Eigen::Vector2i>& occupancy_changes() const { return occupancy_changes_; }

  /// A box of lattice cells, both corners included.
  struct LatticeBox {
    Eigen::Vector2i lo;
    Eigen::Vector2i hi;
  };
  /// For every insertion (a scan, a rectangle) that changed the State of a
  /// cell, the lattice box of the cells it changed, in order. Append-only,
  /// like occupancy_changes(): a reader (GainCache) remembers how many
  /// entries it has read.
  const std::vector<LatticeBox>& state_changes() const { return state_changes_; }

 private:
  // Per beam of a scan: the range up to which it proves free space, and
  // whether it ends on an echo that is inserted as occupied.
  struct BeamFreeSpace {
    std::vector<double> free_range_m;
    std::vector<std::uint8_t> hit;
  };

  // The state of a cell of log-odds `l` (the thresholds).
  CellState StateOfLogOdds(double l) const {
    if (l >= params_.occupied_threshold) return CellState::kOccupied;
    if (l <= params_.free_threshold) return CellState::kFree;
    return CellState::kUnknown;
  }
  // The free range and echo flag of every beam of `scan`.
  BeamFreeSpace FreeSpaceOfBeams(const LaserScan& scan) const;
  // Grows the grid to cover every point the scan touches (its echoes and
  // the ends of its free parts) seen from the laser at `X_WS`.
  void CoverScan(const LaserScan& scan, const Pose2& X_WS, const BeamFreeSpace& beams);
  // Marks the free space along each beam and, with sub-rays, between
  // consecutive beams up to the shorter of their free ranges.
  void MarkScanFree(const LaserScan& scan, const Pose2& X_WS, const BeamFreeSpace& beams);
  // Marks the cells of the echoes occupied (occupied wins over free within
  // one scan).
  void MarkEchoesOccupied(const LaserScan& scan, const Pose2& X_WS, const BeamFreeSpace& beams);
  // Grows the grid so that it covers the axis-aligned box [lo, hi] (world).
  void EnsureCovers(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi);
  // Marks every cell the segment from `from` to `to` crosses (both ends
  // included) for a free update in this scan.
  void MarkRayFree(const Eigen::Vector2d& from, const Eigen::Vector2d& to);
  // Marks cell `index` for a free update unless it is marked already.
  void MarkFree(int index);
  // Applies the marks of this scan and clears them.
  void ApplyMarks();

  ExplorerParams params_;
  GridLimits limits_;
  std::vector<float> log_odds_;
  // Per-scan update marks: 0 none, 1 free, 2 occupied; `touched_` lists the
  // marked cells.
  std::vector<std::uint8_t> marks_;
  std::vector<int> touched_;
  Eigen::Vector2i lattice_origin_ = Eigen::Vector2i::Zero();
  std::vector<Eigen::Vector2i> occupancy_changes_;
  std::vector<LatticeBox> state_changes_;
};

}  // namespace mjslam::explorer
