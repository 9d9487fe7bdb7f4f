#include "explorer/path_planner.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

#include "common/angles.h"
#include "common/check.h"
#include "common/segments.h"

namespace mjslam::explorer {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// How much less clearance a shortcut may keep than the cell path it
// replaces, metres: little, so that a leg through a door crosses it near its
// middle and nearly square to it (at most acos(0.38 / 0.4), 18 deg, off the
// normal of a 0.8 m door).
constexpr double kShortcutClearanceLossM = 0.02;

Eigen::Vector2d LeftNormal(const Eigen::Vector2d& u) { return {-u.y(), u.x()}; }

// A leg passes a narrow place (a door) when its clearance drops below
// clearance_m plus this, metres (doors up to about 1 m).
constexpr double kNarrowMarginM = 0.15;
// A path whose first leg is narrow starts with a turn in place when it
// leaves more than this off the heading, degrees.
constexpr double kAlignBeforeNarrowDeg = 10.0;
// Vertices of a path closer than this to its start are dropped (the path
// starts at the first one farther away), metres: the tracker takes a
// stop-and-turn point as reached once h is within 0.1 m of it, which a
// robot facing a first leg of a cell or two is by turning alone, so it
// turned there without the axle having moved; in front of a door, with each
// replan starting the same first leg again, that was a robot turning left
// and right for good. With 0.2 m the axle drives at least 0.1 m first.
constexpr double kMinFirstLegM = 0.2;

// Whether the segment [a, b] passes a narrow place (sampled every half cell).
bool LegIsNarrow(const NavigationMap& map, const ExplorerParams& params,
                 const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const double length = (b - a).norm();
  const int n =
      std::max(1, static_cast<int>(std::ceil(length / (0.5 * map.grid().resolution()))));
  for (int k = 0; k <= n; ++k) {
    if (map.ClearanceAt(a + (double(k) / n) * (b - a)) < params.clearance_m + kNarrowMarginM) {
      return true;
    }
  }
  return false;
}

// Appends points every `step` along the segment [a, b) (b excluded).
void AppendSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double step, Path* path) {
  const double length = (b - a).norm();
  if (length < 1e-9) return;
  const Eigen::Vector2d u = (b - a) / length;
  const int n = std::max(1, static_cast<int>(std::ceil(length / step)));
  for (int k = 0; k < n; ++k) {
    PathPoint point;
    point.p_W = a + (length * k / n) * u;
    point.heading_rad = std::atan2(u.y(), u.x());
    path->push_back(point);
  }
}

}  // namespace

thread_local std::vector<std::unique_ptr<NavigationMap::NodeTable>> NavigationMap::spare_tables_;

double ClearanceCapM(const ExplorerParams& params) {
  return std::max(params.preferred_clearance_m, params.clearance_m);
}

NavigationMap::NavigationMap(const OccupancyGrid& grid, const ExplorerParams& params,
                             const Eigen::Vector2d& p_W_start, Search search)
    : grid_(grid),
      params_(params),
      p_W_start_(p_W_start),
      start_(grid.CellOf(p_W_start)),
      own_clearance_(ClearanceCapM(params)),
      clearance_(&own_clearance_.values()) {
  own_clearance_.Recompute(grid_);
  Start(search);
}

NavigationMap::NavigationMap(const OccupancyGrid& grid, const ClearanceField& clearance,
                             const ExplorerParams& params, const Eigen::Vector2d& p_W_start,
                             Search search)
    : grid_(grid),
      params_(params),
      p_W_start_(p_W_start),
      start_(grid.CellOf(p_W_start)),
      own_clearance_(ClearanceCapM(params)),
      clearance_(&clearance.values()) {
  MJSLAM_CHECK(clearance.cap_m() == ClearanceCapM(params));
  MJSLAM_CHECK(clearance.limits().width() == grid.width() &&
               clearance.limits().height() == grid.height() &&
               clearance.limits().origin() == grid.origin());
  Start(search);
}

NavigationMap::~NavigationMap() { spare_tables_.push_back(std::move(table_)); }

void NavigationMap::Start(Search search) {
  // A table of the thread's spares (a new one when none is left), with
  // room for every cell and a stamp no entry has yet.
  if (spare_tables_.empty()) {
    table_ = std::make_unique<NodeTable>();
  } else {
    table_ = std::move(spare_tables_.back());
    spare_tables_.pop_back();
  }
  const std::size_t cells = static_cast<std::size_t>(grid_.width()) * grid_.height();
  if (table_->nodes.size() < cells) table_->nodes.resize(cells, Node{0.0f, -1, 0, false, 0});
  if (table_->last_stamp == std::numeric_limits<std::uint32_t>::max()) {
    for (Node& node : table_->nodes) node.stamp = 0;
    table_->last_stamp = 0;
  }
  stamp_ = ++table_->last_stamp;
  // Nothing to search from a start outside the grid: every cost infinite.
  if (!grid_.Contains(start_.x(), start_.y())) {
    expanded_cost_m_ = kInfinity;
    return;
  }
  escape_ = !Comfortable(start_.x(), start_.y());
  start_clearance_ = (*clearance_)[grid_.Index(start_.x(), start_.y())];
  const int start_index = grid_.Index(start_.x(), start_.y());
  Reach(start_index).cost = 0.0f;
  open_.push_back({0.0, 0.0f, start_index});
  if (search == Search::kFull) ExpandTo(kInfinity);
}

double NavigationMap::StepCostFactor(double clearance_m) const {
  const double shortfall =
      std::max(0.0, params_.preferred_clearance_m - clearance_m) / params_.preferred_clearance_m;
  const double narrow =
      std::max(0.0, params_.clearance_m + kNarrowMarginM - clearance_m) / kNarrowMarginM;
  return 1.0 + params_.clearance_cost_weight * shortfall + params_.narrow_cost_weight * narrow;
}

bool NavigationMap::SettleNext(int goal) {
  static constexpr int dx[8] = {1, -1, 0, 0, 1, 1, -1, -1};
  static constexpr int dy[8] = {0, 0, 1, -1, 1, -1, 1, -1};
  const double r = grid_.resolution();
  const Eigen::Vector2i goal_cell =
      goal >= 0 ? grid_.limits().CellOfIndex(goal) : Eigen::Vector2i::Zero();
  // A*'s heuristic: the octile distance, a lower bound of every path's cost
  // (each step costs at least its length), less a little for the float
  // rounding of the stored costs.
  auto heuristic = [&](int ix, int iy) {
    if (goal < 0) return 0.0;
    const int ax = std::abs(ix - goal_cell.x());
    const int ay = std::abs(iy - goal_cell.y());
    return (1.0 - 1e-6) * r * (std::max(ax, ay) + (std::sqrt(2.0) - 1.0) * std::min(ax, ay));
  };
  while (!open_.empty()) {
    std::pop_heap(open_.begin(), open_.end(), std::greater<Open>());
    const Open top = open_.back();
    open_.pop_back();
    Node& node = table_->nodes[top.index];
    if (node.settled || top.cost > node.cost) continue;  // stale entry
    node.settled = true;
    ++settled_;
    const double cost = node.cost;
    const Eigen::Vector2i cell = grid_.limits().CellOfIndex(top.index);
    const int ix = cell.x();
    const int iy = cell.y();
    for (int k = 0; k < 8; ++k) {
      const int jx = ix + dx[k];
      const int jy = iy + dy[k];
      if (!TraversableOnce(jx, jy)) continue;
      // Diagonal moves must not cut the corner of a blocked cell.
      if (k >= 4 && (!TraversableOnce(ix + dx[k], iy) || !TraversableOnce(ix, iy + dy[k]))) {
        continue;
      }
      const int j = grid_.Index(jx, jy);
      const double step = (k < 4 ? r : r * std::sqrt(2.0)) * StepCostFactor((*clearance_)[j]);
      // Compared as stored (float): a double compared with its own rounding
      // would re-push a cell at an equal cost, without end.
      const float next = static_cast<float>(cost + step);
      Node& neighbour = Reach(j);
      if (!neighbour.settled && next < neighbour.cost) {
        neighbour.cost = next;
        neighbour.parent = top.index;
        open_.push_back({next + heuristic(jx, jy), next, j});
        std::push_heap(open_.begin(), open_.end(), std::greater<Open>());
      }
    }
    return true;
  }
  return false;
}

void NavigationMap::ExpandTo(double max_cost_m) {
  MJSLAM_CHECK(!searched_to_goal_);
  while (!open_.empty() && open_.front().priority <= max_cost_m) SettleNext(-1);
  expanded_cost_m_ = open_.empty() ? kInfinity : std::max(expanded_cost_m_, max_cost_m);
}

bool NavigationMap::SearchTo(const Eigen::Vector2i& goal) {
  MJSLAM_CHECK(!searched_to_goal_ && settled_ == 0);
  searched_to_goal_ = true;
  if (!grid_.Contains(goal.x(), goal.y()) || open_.empty()) return false;
  const int goal_index = grid_.Index(goal.x(), goal.y());
  for (;;) {
    const Node* node = Reached(goal_index);
    if (node != nullptr && node->settled) return true;
    if (!SettleNext(goal_index)) return false;
  }
}

double NavigationMap::Clearance(int ix, int iy) const {
  return grid_.Contains(ix, iy) ? (*clearance_)[grid_.Index(ix, iy)] : 0.0;
}

double NavigationMap::ClearanceAt(const Eigen::Vector2d& p_W) const {
  const Eigen::Vector2i c = grid_.CellOf(p_W);
  return Clearance(c.x(), c.y());
}

bool NavigationMap::Traversable(int ix, int iy) const {
  if (!grid_.Contains(ix, iy)) return false;
  const CellState state = grid_.State(ix, iy);
  if (state == CellState::kOccupied) return false;
  // Near a start that lacks clearance: cells no closer to an obstacle than
  // the start (so that a robot stopped in a doorway off its middle gets out
  // without scraping past the jamb).
  if (escape_ && (grid_.CellCenter(ix, iy) - p_W_start_).norm() <= params_.escape_radius_m) {
    return (*clearance_)[grid_.Index(ix, iy)] >= start_clearance_;
  }
  return state == CellState::kFree && (*clearance_)[grid_.Index(ix, iy)] >= params_.clearance_m;
}

bool NavigationMap::Comfortable(int ix, int iy) const {
  return grid_.Contains(ix, iy) && grid_.State(ix, iy) == CellState::kFree &&
         (*clearance_)[grid_.Index(ix, iy)] >= params_.clearance_m;
}

bool NavigationMap::TraversableAt(const Eigen::Vector2d& p_W) const {
  const Eigen::Vector2i c = grid_.CellOf(p_W);
  return Traversable(c.x(), c.y());
}

double NavigationMap::CostTo(int ix, int iy) const {
  if (!grid_.Contains(ix, iy)) return kInfinity;
  const Node* node = Reached(grid_.Index(ix, iy));
  return node != nullptr && node->settled ? node->cost : kInfinity;
}

bool NavigationMap::SegmentTraversable(const Eigen::Vector2d& a_W,
                                       const Eigen::Vector2d& b_W) const {
  const double length = (b_W - a_W).norm();
  const int n = std::max(1, static_cast<int>(std::ceil(length / (0.5 * grid_.resolution()))));
  for (int k = 0; k <= n; ++k) {
    if (!TraversableAt(a_W + (double(k) / n) * (b_W - a_W))) return false;
  }
  return true;
}

std::vector<Eigen::Vector2i> NavigationMap::CellPath(const Eigen::Vector2i& goal) const {
  std::vector<Eigen::Vector2i> cells;
  if (!std::isfinite(CostTo(goal.x(), goal.y()))) return cells;
  for (int i = grid_.Index(goal.x(), goal.y()); i >= 0; i = table_->nodes[i].parent) {
    cells.push_back(grid_.limits().CellOfIndex(i));
  }
  std::reverse(cells.begin(), cells.end());
  return cells;
}

Path SmoothPolyline(const std::vector<Eigen::Vector2d>& vertices, const NavigationMap* map,
                    const ExplorerParams& params) {
  MJSLAM_CHECK(vertices.size() >= 2);
  const int n = static_cast<int>(vertices.size());
  const double step = params.path_step_m;
  Path path;
  Eigen::Vector2d cursor = vertices[0];
  for (int k = 1; k < n; ++k) {
    const Eigen::Vector2d& v = vertices[k];
    if (k == n - 1) {
      AppendSegment(cursor, v, step, &path);
      break;
    }
    const Eigen::Vector2d in = vertices[k] - vertices[k - 1];
    const Eigen::Vector2d out = vertices[k + 1] - vertices[k];
    const Eigen::Vector2d u_in = in.normalized();
    const Eigen::Vector2d u_out = out.normalized();
    const double turn = std::atan2(Cross(u_in, u_out), u_in.dot(u_out));  // signed
    const double phi = std::abs(turn);
    if (phi < 1e-6) continue;  // collinear: no corner
    // Largest tangent length: the whole free part of the first and last
    // legs, half of the inner legs (the neighbouring corner gets the rest).
    const double available_in =
        k == 1 ? (v - cursor).norm() : std::min((v - cursor).norm(), 0.5 * in.norm());
    const double available_out = k + 1 == n - 1 ? out.norm() : 0.5 * out.norm();
    const double tan_half = std::tan(0.5 * phi);
    double radius = std::min(params.max_turn_radius_m,
                             phi > kPi - 1e-6 ? 0.0 : std::min(available_in, available_out) /
                                                           tan_half);
    // No arc next to a door: the robot stops and turns in place, so that it
    // enters and leaves the door straight along the leg (with the axle's
    // clearance, turning in place is safe anywhere on the path).
    if (map != nullptr && (LegIsNarrow(*map, params, vertices[k - 1], v) ||
                           LegIsNarrow(*map, params, v, vertices[k + 1]))) {
      radius = 0.0;
    }
    // Shrink the arc until it stays traversable.
    bool rounded = false;
    Path arc;
    while (radius >= params.min_turn_radius_m) {
      const double d = radius * tan_half;
      const Eigen::Vector2d t_in = v - d * u_in;
      const double sign = turn > 0 ? 1.0 : -1.0;
      const Eigen::Vector2d center = t_in + sign * radius * LeftNormal(u_in);
      const double arc_length = radius * phi;
      const int m = std::max(1, static_cast<int>(std::ceil(arc_length / step)));
      const double start_angle = std::atan2(t_in.y() - center.y(), t_in.x() - center.x());
      arc.clear();
      bool ok = map == nullptr || map->SegmentTraversable(cursor, t_in);
      for (int j = 0; j < m && ok; ++j) {
        const double angle = start_angle + sign * phi * j / m;
        PathPoint point;
        point.p_W = center + radius * Eigen::Vector2d(std::cos(angle), std::sin(angle));
        point.heading_rad = WrapAngle(std::atan2(u_in.y(), u_in.x()) + sign * phi * j / m);
        point.curvature_per_m = sign / radius;
        ok = map == nullptr || map->TraversableAt(point.p_W);
        arc.push_back(point);
      }
      if (ok) {
        AppendSegment(cursor, t_in, step, &path);
        path.insert(path.end(), arc.begin(), arc.end());
        cursor = v + d * u_out;
        rounded = true;
        break;
      }
      radius *= 0.7;
    }
    if (!rounded) {
      // Stop at the corner and turn in place.
      AppendSegment(cursor, v, step, &path);
      PathPoint corner;
      corner.p_W = v;
      corner.heading_rad = std::atan2(u_out.y(), u_out.x());
      corner.turn_in_place = true;
      path.push_back(corner);
      cursor = v;
    }
  }
  // The last point, the goal.
  PathPoint last;
  last.p_W = vertices.back();
  last.heading_rad = path.empty() ? 0.0 : path.back().heading_rad;
  if (!path.empty() && (path.back().p_W - last.p_W).norm() > 1e-9) {
    const Eigen::Vector2d u = last.p_W - path.back().p_W;
    last.heading_rad = std::atan2(u.y(), u.x());
  }
  path.push_back(last);
  // Arc length.
  for (size_t i = 1; i < path.size(); ++i) {
    path[i].s_m = path[i - 1].s_m + (path[i].p_W - path[i - 1].p_W).norm();
  }

  // Speed profile: curvature limits, then acceleration toward every stop.
  const int size = static_cast<int>(path.size());
  for (int i = 0; i < size; ++i) {
    PathPoint& point = path[i];
    double v = params.cruise_speed_mps;
    const double kappa = std::abs(point.curvature_per_m);
    if (kappa > 0.0) {
      v = std::min({v, params.max_angular_speed_radps / kappa,
                    std::sqrt(params.max_lateral_accel_mps2 / kappa)});
    }
    // Slower where the clearance is small (doors), from the narrow speed
    // at clearance_m to the cruise speed at the preferred clearance.
    if (map != nullptr && params.preferred_clearance_m > params.clearance_m) {
      const double fraction =
          std::clamp((map->ClearanceAt(point.p_W) - params.clearance_m) /
                         (params.preferred_clearance_m - params.clearance_m),
                     0.0, 1.0);
      v = std::min(v, params.narrow_speed_mps +
                          fraction * (params.cruise_speed_mps - params.narrow_speed_mps));
    }
    if (point.turn_in_place || i + 1 == size) v = 0.0;
    point.speed_mps = v;
  }
  for (int i = size - 2; i >= 0; --i) {
    const double ds = path[i + 1].s_m - path[i].s_m;
    path[i].speed_mps = std::min(
        path[i].speed_mps,
        std::sqrt(path[i + 1].speed_mps * path[i + 1].speed_mps +
                  2.0 * params.max_linear_accel_mps2 * ds));
  }
  return path;
}

Path PlanPath(const NavigationMap& map, const ExplorerParams& params,
              const Eigen::Vector2d& p_W_goal, double heading_rad) {
  const OccupancyGrid& grid = map.grid();
  const std::vector<Eigen::Vector2i> cells = map.CellPath(grid.CellOf(p_W_goal));
  if (cells.empty()) return {};
  // Cell centres, starting at the start point itself.
  std::vector<Eigen::Vector2d> points;
  points.push_back(grid.CellCenter(cells.front().x(), cells.front().y()));
  for (size_t i = 1; i < cells.size(); ++i) {
    points.push_back(grid.CellCenter(cells[i].x(), cells[i].y()));
  }
  if (points.size() == 1) points.push_back(points.front());
  // Line-of-sight shortcuts that keep the clearance the cell path had over
  // the part they replace (less one cell): a shortcut must not hug the jamb
  // of a door that the cell path passed in the middle.
  std::vector<double> clearance(points.size());
  for (size_t k = 0; k < points.size(); ++k) clearance[k] = map.ClearanceAt(points[k]);
  auto shortcut_ok = [&](size_t from, size_t to) {
    if (!map.SegmentTraversable(points[from], points[to])) return false;
    double needed = params.preferred_clearance_m;
    for (size_t k = from; k <= to; ++k) needed = std::min(needed, clearance[k]);
    needed -= kShortcutClearanceLossM;
    const Eigen::Vector2d leg = points[to] - points[from];
    const double length = leg.norm();
    const int n = std::max(1, static_cast<int>(std::ceil(length / (0.5 * grid.resolution()))));
    for (int k = 0; k <= n; ++k) {
      const Eigen::Vector2d p = points[from] + (double(k) / n) * leg;
      if (map.ClearanceAt(p) < needed) return false;
    }
    return true;
  };
  std::vector<Eigen::Vector2d> vertices = {points.front()};
  size_t i = 0;
  while (i + 1 < points.size()) {
    size_t j = i + 1;
    while (j + 1 < points.size() && shortcut_ok(i, j + 1)) ++j;
    vertices.push_back(points[j]);
    i = j;
  }
  // Drop a degenerate first leg.
  if (vertices.size() > 2 && (vertices[1] - vertices[0]).norm() < 1e-9) {
    vertices.erase(vertices.begin() + 1);
  }
  // Start at the first vertex at least kMinFirstLegM from the start (the
  // tracker steers h there when it is not reached yet).
  const Eigen::Vector2d start = vertices.front();
  while (vertices.size() > 2 && (vertices[1] - start).norm() < kMinFirstLegM) {
    vertices.erase(vertices.begin());
  }
  if ((vertices.back() - vertices.front()).norm() < 1e-9) {
    PathPoint only;
    only.p_W = vertices.front();
    only.heading_rad = heading_rad;
    return {only};
  }
  Path path = SmoothPolyline(vertices, &map, params);
  // Turn toward the first leg first when it leaves far off the heading.
  if (path.size() >= 2) {
    const double error = WrapAngle(path.front().heading_rad - heading_rad);
    // Where the axle has room to turn: not in the door itself, where a
    // replan would otherwise turn the robot against the jambs.
    const bool align = LegIsNarrow(map, params, vertices[0], vertices[1]) &&
                       map.ClearanceAt(vertices[0]) >= params.turn_clearance_m;
    const double limit_deg = align ? std::min(kAlignBeforeNarrowDeg, params.turn_in_place_deg)
                                   : params.turn_in_place_deg;
    if (std::abs(error) > DegToRad(limit_deg)) {
      path.front().turn_in_place = true;
      path.front().speed_mps = 0.0;
      path.front().curvature_per_m = 0.0;
    }
  }
  return path;
}

Path PathOfPointH(const Path& axle_path, double a_m, double heading_rad) {
  Path path = axle_path;
  for (size_t i = 0; i < path.size(); ++i) {
    // At a stop-and-turn point h still has the heading it arrived with (the
    // robot's own at the start); it reaches the next point by the turn.
    const double arriving = i == 0 ? heading_rad : axle_path[i - 1].heading_rad;
    const double th = axle_path[i].turn_in_place ? arriving : axle_path[i].heading_rad;
    path[i].p_W = axle_path[i].p_W + a_m * Eigen::Vector2d(std::cos(th), std::sin(th));
  }
  for (size_t i = 1; i < path.size(); ++i) {
    path[i].s_m = path[i - 1].s_m + (path[i].p_W - path[i - 1].p_W).norm();
  }
  return path;
}

bool PathClearOfPoints(const Path& path, int from,
                       const std::vector<Eigen::Vector2d>& obstacles_W, double clearance_m) {
  const double squared = clearance_m * clearance_m;
  for (int i = std::max(0, from); i < static_cast<int>(path.size()); ++i) {
    for (const Eigen::Vector2d& q : obstacles_W) {
      if ((path[i].p_W - q).squaredNorm() < squared) return false;
    }
  }
  return true;
}

}  // namespace mjslam::explorer
