#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "common/params.h"
#include "eval/map_types.h"

namespace mjslam::eval {

/// The footprint of one wall in the floor plane: a rectangle given by its
/// four corners p_W (metres, world frame W), in order around it (clockwise
/// or counter-clockwise), at any yaw.
struct WallRectangle {
  std::array<Eigen::Vector2d, 4> corners_W;
};

/// Tolerances of BuildGroundTruthMap.
struct GroundTruthParams {
  /// Walls closer than this count as touching (no free space between them),
  /// and boundary pieces closer than this join, metres.
  double touch_tolerance_m = 1e-4;
  /// Boundary segments shorter than this are dropped (slivers), metres.
  double min_segment_length_m = 1e-3;
  /// Two boundary segments meeting at a smaller angle are no corner, degrees.
  double corner_min_angle_deg = 5.0;

  std::vector<ParamProblem> Validate() const;
  void ValidateOrThrow() const { ThrowIfProblems(Validate(), "ground truth"); }
};

/// The true map of a world from its wall footprints: the boundary of the
/// union of the rectangles (overlapping and touching walls merge). Every
/// maximal straight piece of that boundary is a line feature: (r, al) of its
/// infinite line in canonical form (r >= 0, al in (-pi, pi]; slam/README.md,
/// "Models") and its segment p_WA -> p_WB, traversed with the obstacle on the
/// left. Every point where two boundary segments meet at an angle of at least
/// corner_min_angle_deg is a corner, convex when the obstacle's angle there is
/// below 180 degrees (it points into the free space), concave otherwise (an
/// inside corner of a room). Lines come first (ids 0, 1, ...), then corners;
/// covariances are zero. Pillars (circles) are obstacles, not features: the
/// caller leaves them out.
///
/// Method: each rectangle edge is split where it enters or leaves another
/// rectangle (grown by touch_tolerance_m); a piece is kept when the point just
/// outside its midpoint (touch_tolerance_m along the outward normal) lies in
/// no other rectangle; kept pieces on one line that overlap or touch merge.
///
/// Throws std::invalid_argument naming the wall (by index) when its corners
/// are not finite or do not form a rectangle with sides of at least
/// min_segment_length_m; ParamError for invalid params.
Map BuildGroundTruthMap(const std::vector<WallRectangle>& walls,
                        const GroundTruthParams& params = {});

/// The features of `truth` (from BuildGroundTruthMap of `walls`) that face the
/// free space reachable from p_W_start: a flood fill over a grid of
/// `cell_m` cells (a cell is free when its centre is in no wall) from the
/// cell of p_W_start; a line is kept when the point 1.5 cells off its
/// segment's midpoint on the free side lies in a reached cell, a corner when
/// the point 1.5 cells along its free direction does. So the outer faces of a
/// closed building, which no robot inside can see, are left out. Ids are
/// renumbered in order. Throws std::invalid_argument when p_W_start is inside
/// a wall or cell_m <= 0.
Map ReachableFeatures(const Map& truth, const std::vector<WallRectangle>& walls,
                      const Eigen::Vector2d& p_W_start, double cell_m = 0.05);

}  // namespace mjslam::eval
