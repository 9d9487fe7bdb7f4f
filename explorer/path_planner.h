#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "common/grid2.h"
#include "explorer/clearance_field.h"
#include "explorer/explorer_params.h"
#include "explorer/occupancy_grid.h"

namespace mjslam::explorer {

/// One point of a planned path of h, in the world frame W.
struct PathPoint {
  /// Position of h, metres.
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();
  /// Direction of travel, radians.
  double heading_rad = 0.0;
  /// Signed curvature (left positive), 1/m; 0 at stop-and-turn points.
  double curvature_per_m = 0.0;
  /// Reference speed of h, m/s (0 at stop-and-turn points and at the end).
  double speed_mps = 0.0;
  /// Arc length from the start, metres.
  double s_m = 0.0;
  /// The robot stops here and turns in place to `heading_rad` (a corner that
  /// no arc of at least `min_turn_radius_m` could round).
  bool turn_in_place = false;
};

/// A path is its points in order; empty when there is none.
using Path = std::vector<PathPoint>;

/// The cap of the clearance the planner needs, metres: the larger of
/// `preferred_clearance_m` and `clearance_m` (no rule reads more).
double ClearanceCapM(const ExplorerParams& params);

/// The grid seen by the planner: the clearance of every cell (a
/// ClearanceField capped at ClearanceCapM) and the cost to reach cells from a
/// start point (Dijkstra, 8-connected, on known-free cells with at least
/// `clearance_m`; each step costs its length times 1 +
/// `clearance_cost_weight` * the shortfall of clearance below
/// `preferred_clearance_m`, relative, + `narrow_cost_weight` * the shortfall
/// below `clearance_m` + 0.15 m relative to 0.15 m, which puts a path through
/// a door on its clearance ridge). When the start cell itself lacks that
/// clearance, cells within `escape_radius_m` of the start need only be not
/// occupied and no closer to an occupied cell than the start, so that a
/// robot stopped close to a wall can plan its way out.
///
/// The search runs on demand and touches only the cells it reaches (their
/// costs and traversability, computed once per cell, live in a per-cell
/// table that the maps of one thread reuse, each entry stamped with the map
/// that wrote it, so that a new map clears nothing), so that its cost follows
/// the cells searched, not the grid's size: `Search::kFull`
/// costs every reachable cell at construction; with `Search::kOnDemand` the
/// caller runs ExpandTo (Dijkstra up to a cost, resumable) or SearchTo (A* to
/// one cell, octile distance as the heuristic), not both.
class NavigationMap {
 public:
  /// How much the constructor searches.
  enum class Search {
    /// Every cell reachable from the start (the whole Dijkstra).
    kFull,
    /// Nothing: ExpandTo or SearchTo search what is needed.
    kOnDemand,
  };

  /// Builds the map of `grid` (which must outlive it) from `p_W_start`,
  /// computing the clearance over the whole grid.
  NavigationMap(const OccupancyGrid& grid, const ExplorerParams& params,
                const Eigen::Vector2d& p_W_start, Search search = Search::kFull);
  /// The same with a clearance field kept up to date by the caller: it must
  /// be current for `grid` (its limits equal the grid's) with a cap of
  /// ClearanceCapM(params), and outlive the map.
  NavigationMap(const OccupancyGrid& grid, const ClearanceField& clearance,
                const ExplorerParams& params, const Eigen::Vector2d& p_W_start,
                Search search = Search::kFull);
  ~NavigationMap();
  NavigationMap(const NavigationMap&) = delete;
  NavigationMap& operator=(const NavigationMap&) = delete;

  /// Dijkstra: settles every reachable cell whose cost is at most
  /// `max_cost_m` (resumes where the last call stopped). Not after SearchTo.
  void ExpandTo(double max_cost_m);
  /// The cost up to which every cell's cost is final (infinity once every
  /// reachable cell is settled), metres.
  double expanded_cost() const { return expanded_cost_m_; }
  /// A*: settles cells until `goal` is settled (its cheapest path found) or
  /// none is left; true when the goal is reachable. Only on a map built with
  /// Search::kOnDemand that has not searched yet.
  bool SearchTo(const Eigen::Vector2i& goal);
  /// Number of cells settled so far (the search's cost).
  int settled_cells() const { return settled_; }

  const OccupancyGrid& grid() const { return grid_; }
  /// Clearance of a cell, metres (at most ClearanceCapM; 0 outside the
  /// grid).
  double Clearance(int ix, int iy) const;
  /// Clearance at a world point (its cell), metres.
  double ClearanceAt(const Eigen::Vector2d& p_W) const;
  /// Whether h may stand in the cell (the rules above).
  bool Traversable(int ix, int iy) const;
  /// Whether h may stand at the world point.
  bool TraversableAt(const Eigen::Vector2d& p_W) const;
  /// Whether the cell is known free with at least `clearance_m` (a goal must
  /// be; the escape rule does not apply).
  bool Comfortable(int ix, int iy) const;
  /// Path cost from the start to the cell, metres, once the search has
  /// settled it; infinity if it is unreachable or not settled yet.
  double CostTo(int ix, int iy) const;
  /// Whether every point of the segment is traversable (sampled at half a cell).
  bool SegmentTraversable(const Eigen::Vector2d& a_W, const Eigen::Vector2d& b_W) const;
  /// Cells from the start to `goal` (inclusive), empty if not settled.
  std::vector<Eigen::Vector2i> CellPath(const Eigen::Vector2i& goal) const;
  /// The start cell.
  Eigen::Vector2i start_cell() const { return start_; }

 private:
  // A cell looked at by the search: its cost so far (float, compared as
  // stored; infinite until reached), the linear index of the cell before it
  // (-1: none), settled, whether it is Traversable (0: not known yet, 1: no,
  // 2: yes); the stamp of the map that wrote it (any other stamp: not looked
  // at).
  struct Node {
    float cost;
    int parent;
    std::uint32_t stamp;
    bool settled;
    std::uint8_t traversable;
  };
  // The per-cell table of one thread's maps (see the class comment).
  struct NodeTable {
    std::vector<Node> nodes;
    std::uint32_t last_stamp = 0;
  };
  // An entry of the open list: priority (cost, plus the heuristic for A*),
  // cost when pushed, linear index; ordered by priority, then index.
  struct Open {
    double priority;
    float cost;
    int index;
    bool operator>(const Open& other) const {
      return priority != other.priority ? priority > other.priority : index > other.index;
    }
  };
  // Sets up the start (escape rule, open list) after the constructors.
  void Start(Search search);
  // Settles the cheapest open cell and relaxes its neighbours; `goal` >= 0
  // adds A*'s heuristic toward that linear index. False when none is left.
  bool SettleNext(int goal);
  // The cost of a step into a cell of this clearance, per metre of its length.
  double StepCostFactor(double clearance_m) const;

  const OccupancyGrid& grid_;
  ExplorerParams params_;
  Eigen::Vector2d p_W_start_;
  Eigen::Vector2i start_;
  // Whether the escape rule applies (the start lacks clearance).
  bool escape_ = false;
  // The start cell's clearance, metres.
  float start_clearance_ = 0.0f;
  // The clearance computed by the first constructor (unused by the second).
  ClearanceField own_clearance_;
  // Per cell of the grid: clearance, metres (the field's values).
  const Grid2<float>* clearance_;
  // Node tables no map of this thread holds now, for the next maps.
  static thread_local std::vector<std::unique_ptr<NodeTable>> spare_tables_;
  // The cell's node, by linear index: looked at by this map, or null.
  const Node* Reached(int index) const {
    const Node& node = table_->nodes[index];
    return node.stamp == stamp_ ? &node : nullptr;
  }
  // The cell's node, made a fresh one (infinite cost) if not looked at yet.
  Node& Reach(int index) {
    Node& node = table_->nodes[index];
    if (node.stamp != stamp_) {
      node = Node{std::numeric_limits<float>::infinity(), -1, stamp_, false, 0};
    }
    return node;
  }
  // Traversable(ix, iy), computed once per cell.
  bool TraversableOnce(int ix, int iy) {
    if (!grid_.Contains(ix, iy)) return false;
    Node& node = Reach(grid_.Index(ix, iy));
    if (node.traversable == 0) node.traversable = Traversable(ix, iy) ? 2 : 1;
    return node.traversable == 2;
  }

  // The cells looked at (a table taken from the thread's spares, given
  // back by the destructor), this map's stamp in it, and the open list.
  std::unique_ptr<NodeTable> table_;
  std::uint32_t stamp_ = 0;
  std::vector<Open> open_;
  double expanded_cost_m_ = 0.0;
  int settled_ = 0;
  // Whether SearchTo (A*) has run: ExpandTo's costs would not be final.
  bool searched_to_goal_ = false;
};

/// Plans a kinematically feasible path of h from the map's start to
/// `p_W_goal` (which must be reachable in `map`): the Dijkstra cell path,
/// shortened by line of sight over traversable cells, then its corners rounded
/// with circular arcs of radius between `min_turn_radius_m` and
/// `max_turn_radius_m` that stay traversable (a corner where none fits becomes
/// a stop-and-turn point: the differential drive turns in place there). The
/// speed profile respects `cruise_speed_mps`, the angular speed limit and the
/// lateral acceleration on arcs, and `max_linear_accel_mps2` toward every stop.
/// `heading_rad` is the robot's heading: when the first leg leaves more than
/// `turn_in_place_deg` off it, the path starts with a stop-and-turn point.
/// Returns an empty path when the goal is unreachable.
Path PlanPath(const NavigationMap& map, const ExplorerParams& params,
              const Eigen::Vector2d& p_W_goal, double heading_rad);

/// Rounds the corners of a polyline as PlanPath does (exposed for tests):
/// `vertices` in W, at least two; `map` may be null (no collision check).
Path SmoothPolyline(const std::vector<Eigen::Vector2d>& vertices, const NavigationMap* map,
                    const ExplorerParams& params);

/// The path of h (`a_m` ahead of the axle, along the heading) when the axle
/// follows `axle_path` (a PlanPath of the axle): each point moved by a_m along
/// its heading; at a stop-and-turn point h keeps the heading it arrives
/// with (`heading_rad`, the robot's, for the first point) and the turn in
/// place carries it to the next point. Arc lengths are those of h.
Path PathOfPointH(const Path& axle_path, double a_m, double heading_rad);

/// Whether every point of `path` from index `from` on keeps `clearance_m`
/// from every point of `obstacles_W` (scan echoes), metres.
bool PathClearOfPoints(const Path& path, int from,
                       const std::vector<Eigen::Vector2d>& obstacles_W, double clearance_m);

}  // namespace mjslam::explorer
