#include "explorer/explorer.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

#include "common/angles.h"
#include "common/check.h"
#include "common/grid2.h"
#include "explorer/frontiers.h"
#include "explorer/point_h_controller.h"

namespace mjslam::explorer {
namespace {

const ExplorerParams& Validated(const ExplorerParams& params, double a_m) {
  params.ValidateOrThrow();
  if (!(a_m > 0.0)) {
    throw ParamError("robot.control_point_offset_m: expected a value > 0 (got " +
                     ValueText(a_m) + ")");
  }
  return params;
}

// Path points closer than this to h are not checked against the scan (the
// robot is already there), metres.
constexpr double kPathCheckSkipM = 0.3;
// Path points farther along than this are not checked against the scan, m.
constexpr double kPathCheckRangeM = 3.0;
// After the safety layer has held the robot still this long, it backs up
// (when that is safe) for kRecoveryS at kRecoverySpeedMps, so that it can
// turn again: seconds, seconds, m/s.
constexpr double kRecoveryAfterS = 1.0;
constexpr double kRecoveryS = 1.5;
constexpr double kRecoverySpeedMps = 0.1;
// In-place turn rate of a recovery that can neither back up nor drive
// forward, rad/s.
constexpr double kRecoveryTurnRadps = 0.4;
// The first cost bound of the search for a goal, metres (then doubled).
constexpr double kFirstSearchCostM = 4.0;
// A back-out drives the planned path backward to the first point where the
// axle has turning room and this much further, so that the tracker's end
// (within goal_tolerance_m) lies past that point, metres.
constexpr double kBackOutPastRoomM = 0.3;
// A path that starts with a turn in place of more than this reverses the
// robot's direction, degrees.
constexpr double kReverseDeg = 90.0;
// The turn that faces a frontier point at a goal reached ends within this
// bearing, degrees, or after this time, seconds.
constexpr double kFacedDeg = 5.0;
constexpr double kMaxFaceS = 8.0;
// A far viewpoint should look at its frontier point along the way into the
// unknown beyond it: each radian between the two costs this much, metres.
constexpr double kFarLookCostPerRad = 10.0;

// Whether no occupied cell lies on the segment from `from_W` to `to_W` (the
// cell of `to_W` excluded): a viewpoint must see its frontier point.
bool SeesPoint(const OccupancyGrid& grid, const Eigen::Vector2d& from_W,
               const Eigen::Vector2d& to_W) {
  const Eigen::Vector2i last = grid.CellOf(to_W);
  bool clear = true;
  TraverseSegment(grid.limits(), from_W, to_W, [&](int ix, int iy) {
    if (Eigen::Vector2i(ix, iy) != last && grid.State(ix, iy) == CellState::kOccupied) {
      clear = false;
    }
  });
  return clear;
}

// The unit direction from `p_W` into the unknown around it: away from the
// free space it is seen from, i.e. minus the mean of the unit vectors of
// rays from it, each weighted by the free cells it crosses within `radius_m`
// before the first cell that is not free (an unknown cell of a wall that was
// only grazed, or the unknown outside the building, does not pull it);
// zero when none.
Eigen::Vector2d UnknownDirection(const OccupancyGrid& grid, const Eigen::Vector2d& p_W,
                                 double radius_m) {
  constexpr int kRays = 72;
  const double step = grid.resolution();
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int k = 0; k < kRays; ++k) {
    const double angle = 2.0 * kPi * k / kRays;
    const Eigen::Vector2d u(std::cos(angle), std::sin(angle));
    int free = 0;
    for (double s = step; s <= radius_m; s += step) {
      const Eigen::Vector2i c = grid.CellOf(p_W + s * u);
      if (!grid.Contains(c.x(), c.y()) || grid.State(c.x(), c.y()) != CellState::kFree) break;
      ++free;
    }
    sum -= free * u;
  }
  return sum.norm() > 0.0 ? Eigen::Vector2d(sum.normalized()) : Eigen::Vector2d::Zero();
}

}  // namespace

Explorer::Explorer(const ExplorerParams& params, double a_m)
    : params_(Validated(params, a_m)),
      a_m_(a_m),
      grid_(params),
      clearance_(ClearanceCapM(params)),
      tracker_(params, a_m),
      reverse_tracker_(params, a_m) {
  if (params_.initial_turn_deg <= 0.0) phase_ = Phase::kExploring;
}

std::optional<Eigen::Vector2d> Explorer::goal() const {
  if (!has_goal_) return std::nullopt;
  return goal_W_;
}

std::optional<Eigen::Vector2d> Explorer::goal_frontier() const {
  if (!has_goal_) return std::nullopt;
  return frontier_W_;
}

std::vector<ExplorerLogRow> Explorer::LogRows() const {
  std::vector<ExplorerLogRow> rows;
  for (size_t i = 0; i < frontier_points_.size(); ++i) {
    rows.push_back({"frontier", static_cast<int>(i), frontier_points_[i].x(),
                    frontier_points_[i].y()});
  }
  if (has_goal_) rows.push_back({"goal", 0, goal_W_.x(), goal_W_.y()});
  const Path& path = tracker_.path();
  for (size_t i = 0; i < path.size(); ++i) {
    rows.push_back({"path", static_cast<int>(i), path[i].p_W.x(), path[i].p_W.y()});
  }
  return rows;
}

bool Explorer::Blacklisted(const Eigen::Vector2d& p_W, bool* failed, int* looks) const {
  bool near = false;
  if (failed != nullptr) *failed = false;
  if (looks != nullptr) *looks = 0;
  for (const BlacklistEntry& entry : blacklist_) {
    if ((entry.p_W - p_W).norm() < params_.blacklist_radius_m) {
      near = true;
      if (failed != nullptr && entry.failed) *failed = true;
      if (looks != nullptr && !entry.failed && entry.frontier) ++*looks;
    }
  }
  return near;
}

void Explorer::DropGoal(bool blacklist, bool failed) {
  if (has_goal_ && blacklist) {
    blacklist_.push_back({frontier_W_, failed, true});
    blacklist_.push_back({goal_W_, failed, false});
  }
  has_goal_ = false;
  backing_out_ = false;
  back_out_held_ = false;
  facing_ = false;
  tracker_.Clear();
  reverse_tracker_.Clear();
  ++log_version_;
}

std::vector<Eigen::Vector2d> Explorer::NearbyObstacles(const Pose2& X_WR) const {
  std::vector<Eigen::Vector2d> points;
  const Eigen::Vector2d h = X_WR.translation();
  const double range = params_.safety_range_m;
  for (const Eigen::Vector2d& p : scan_points_W_) {
    if ((p - h).norm() < range) points.push_back(p);
  }
  // Occupied cells cover what the laser does not see (behind the robot).
  const Eigen::Vector2i lo = grid_.CellOf(h.array() - range);
  const Eigen::Vector2i hi = grid_.CellOf(h.array() + range);
  for (int iy = std::max(0, lo.y()); iy <= std::min(grid_.height() - 1, hi.y()); ++iy) {
    for (int ix = std::max(0, lo.x()); ix <= std::min(grid_.width() - 1, hi.x()); ++ix) {
      if (grid_.State(ix, iy) != CellState::kOccupied) continue;
      const Eigen::Vector2d c = grid_.CellCenter(ix, iy);
      if ((c - h).norm() < range) points.push_back(c);
    }
  }
  return points;
}

Eigen::Vector2d Explorer::AxleOf(const Pose2& X_WR) const {
  return X_WR * Eigen::Vector2d(-a_m_, 0.0);
}

bool Explorer::PlanToGoal(const NavigationMap& map, const Pose2& X_WR, double t_s) {
  // The plan is the axle's (its clearance covers the body in every
  // heading); the tracker follows the path of h that goes with it.
  const Path axle_path = PlanPath(map, params_, goal_W_, X_WR.theta);
  last_plan_t_s_ = t_s;
  if (axle_path.empty()) return false;
  // Progress: the axle's path to the goal, planned from where the axle is,
  // got shorter (turning in place or swinging h is none).
  if (axle_path.back().s_m < best_remaining_m_ - params_.progress_min_m) {
    best_remaining_m_ = axle_path.back().s_m;
    progress_t_s_ = t_s;
  }
  Path path = PathOfPointH(axle_path, a_m_, X_WR.theta);
  // A path that reverses the robot's direction from a place where it cannot
  // turn (a door, a narrow strip): drive its first part backward, the way
  // the robot came, to where the axle has room to turn.
  const double turn = std::abs(WrapAngle(path.front().heading_rad - X_WR.theta));
  backing_out_ = path.front().turn_in_place && turn > DegToRad(kReverseDeg) &&
                 map.ClearanceAt(AxleOf(X_WR)) < params_.turn_clearance_m && !back_out_held_;
  if (backing_out_) StartBackOut(map, axle_path, X_WR, t_s);
  tracker_.SetPath(std::move(path));
  ++log_version_;
  return true;
}

bool Explorer::HasTurningRoom(const Eigen::Vector2d& axle_W) {
  clearance_.Update(grid_);
  const Eigen::Vector2i cell = grid_.CellOf(axle_W);
  return grid_.Contains(cell.x(), cell.y()) &&
         clearance_.Clearance(cell.x(), cell.y()) >= params_.turn_clearance_m;
}

void Explorer::StartBackOut(const NavigationMap& map, const Path& axle_path, const Pose2& X_WR,
                            double t_s) {
  // The axle path's first part, to the first point with turning room (and
  // kBackOutPastRoomM on), at no more than narrow_speed_mps: the laser does
  // not see behind the robot. The robot driving backward is a robot facing
  // the other way driving forward (same axle, heading + pi, speed negated):
  // its point h lies a_m behind the axle, and a PathTracker follows the
  // path of that point.
  Path reverse;
  double room_s = std::numeric_limits<double>::infinity();
  for (const PathPoint& point : axle_path) {
    if (point.s_m > room_s + kBackOutPastRoomM) break;
    reverse.push_back(point);
    if (!std::isfinite(room_s) && map.ClearanceAt(point.p_W) >= params_.turn_clearance_m) {
      room_s = point.s_m;
    }
  }
  for (PathPoint& point : reverse) {
    point.speed_mps = std::min(point.speed_mps, params_.narrow_speed_mps);
  }
  reverse.front().turn_in_place = false;
  reverse.front().speed_mps = params_.narrow_speed_mps;
  reverse.back().speed_mps = 0.0;
  const Pose2 X_WF = FacingBack(X_WR);
  reverse_tracker_.SetPath(PathOfPointH(reverse, a_m_, X_WF.theta));
  back_out_best_s_ = 0.0;
  back_out_progress_t_s_ = t_s;
}

Pose2 Explorer::FacingBack(const Pose2& X_WR) const {
  const Eigen::Vector2d h = X_WR.translation() -
                            2.0 * a_m_ * Eigen::Vector2d(std::cos(X_WR.theta), std::sin(X_WR.theta));
  return Pose2(h.x(), h.y(), WrapAngle(X_WR.theta + kPi));
}

Twist2 Explorer::BackOut(const Pose2& X_WR, double t_s, double dt_s) {
  const bool room = HasTurningRoom(AxleOf(X_WR));
  // Progress along the path backed: as a goal's, progress_min_m within
  // progress_timeout_s.
  const Path& reverse = reverse_tracker_.path();
  const double backed_s = reverse.empty() ? 0.0 : reverse[reverse_tracker_.index()].s_m;
  if (backed_s >= back_out_best_s_ + params_.progress_min_m) {
    back_out_best_s_ = backed_s;
    back_out_progress_t_s_ = t_s;
  }
  const bool stalled = t_s - back_out_progress_t_s_ > params_.progress_timeout_s;
  if (room || reverse_tracker_.done() || blocked_s_ > 0.0 || stalled) {
    backing_out_ = false;
    // Ended without turning room: no new back-out for this goal (the
    // recovery and the goal's clocks take over), or the two could alternate.
    back_out_held_ = !room;
    // Backing out to turning room is a manoeuvre, not a lack of progress.
    if (room) progress_t_s_ = t_s;
    reverse_tracker_.Clear();
    Replan(X_WR, t_s);
    return tracker_.last_command();
  }
  // The tracker of the robot facing back, its last command mirrored.
  const Twist2 last = tracker_.last_command();
  reverse_tracker_.set_last_command(Twist2{-last.v_mps, last.w_radps});
  const Twist2 mirrored = reverse_tracker_.Command(FacingBack(X_WR), dt_s);
  return Twist2{-mirrored.v_mps, mirrored.w_radps};
}

std::vector<Explorer::Candidate> Explorer::ScoreFrontiers(
    NavigationMap& map, const std::vector<Eigen::Vector2d>& points, bool* unreachable) {
  // The points with gain that are not blacklisted (no search needed).
  std::vector<Candidate> pending;
  for (const Eigen::Vector2d& p : points) {
    const double gain = gains_.Gain(grid_, p, params_.gain_radius_m);
    if (gain < params_.min_gain_m2) continue;
    bool failed = false;
    int looks = 0;
    const bool blacklisted = Blacklisted(p, &failed, &looks);
    if (blacklisted) *unreachable = *unreachable || failed;
    // Near a goal reached once (the robot looked from there and gain is
    // left: a strip seen at a slant from its mouth): a second look.
    if (blacklisted && (failed || looks != 1)) continue;
    frontier_points_.push_back(p);
    pending.push_back({p, p, params_.gain_weight_per_m2 * gain,
                       static_cast<int>(pending.size()), blacklisted, blacklisted});
  }
  // Their viewpoints' costs: the search grows (doubling its cost bound)
  // until the best candidate costed cannot be beaten by one still pending,
  // each of which costs more than the bound, so that a goal near the robot
  // is found without searching the whole map. Far viewpoints (beyond
  // view_distance_m) only when no candidate has a near one: they need the
  // whole search.
  std::vector<Candidate> candidates;
  std::vector<Candidate> far_candidates;
  for (double bound = kFirstSearchCostM; !pending.empty(); bound *= 2.0) {
    map.ExpandTo(bound);
    const double reach = map.expanded_cost();
    std::vector<Candidate> still;
    for (Candidate& candidate : pending) {
      double cost = std::numeric_limits<double>::infinity();
      if (!candidate.second_look) {
        cost = BestViewpoint(map, candidate.frontier_W, params_.view_distance_m, false,
                             &candidate.goal_W);
      }
      // Final when at most `reach`: every cell not settled costs more. A
      // viewpoint near a goal tried (reached or failed) is no use: the robot
      // looked from there.
      bool failed = false;
      const bool tried = cost <= reach && Blacklisted(candidate.goal_W, &failed);
      candidate.far_only = candidate.far_only || tried;
      if (std::isfinite(reach) && (tried || !(cost <= reach))) {
        still.push_back(candidate);  // costed later, or looked at from afar
        continue;
      }
      // Searched everything and no near viewpoint to try (a strip too narrow
      // to turn in, a goal tried, a second look): one within
      // max_view_distance_m from which the laser sees the point, away from
      // the goals tried.
      const bool far = tried || !std::isfinite(cost);
      if (far) {
        cost = BestViewpoint(map, candidate.frontier_W, params_.max_view_distance_m, true,
                             &candidate.goal_W);
      }
      if (!std::isfinite(cost)) {
        // Unreachable: failed before, or no viewpoint at all (a point
        // looked at from a goal reached is not).
        *unreachable = *unreachable || failed || (!tried && !candidate.second_look);
        continue;
      }
      candidate.score -= cost;
      (far ? far_candidates : candidates).push_back(candidate);
    }
    pending.swap(still);
    double best = -std::numeric_limits<double>::infinity();
    for (const Candidate& c : candidates) best = std::max(best, c.score);
    double pending_best = -std::numeric_limits<double>::infinity();
    for (const Candidate& c : pending) {
      if (!c.far_only) pending_best = std::max(pending_best, c.score - reach);
    }
    if (!candidates.empty() && best >= pending_best) break;
  }
  if (candidates.empty()) candidates.swap(far_candidates);
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.score != b.score ? a.score > b.score : a.order < b.order;
  });
  return candidates;
}

double Explorer::BestViewpoint(const NavigationMap& map, const Eigen::Vector2d& p_W,
                               double radius_m, bool far,
                               Eigen::Vector2d* viewpoint_W) const {
  const Eigen::Vector2d beyond =
      far ? UnknownDirection(grid_, p_W, params_.gain_radius_m) : Eigen::Vector2d::Zero();
  const double r = grid_.resolution();
  const int window = static_cast<int>(std::ceil(radius_m / r));
  const Eigen::Vector2i c = grid_.CellOf(p_W);
  double best = std::numeric_limits<double>::infinity();
  for (int iy = c.y() - window; iy <= c.y() + window; ++iy) {
    for (int ix = c.x() - window; ix <= c.x() + window; ++ix) {
      const double cost = map.CostTo(ix, iy);
      if (!std::isfinite(cost) || !map.Comfortable(ix, iy) ||
          map.Clearance(ix, iy) < params_.turn_clearance_m) {
        continue;
      }
      const Eigen::Vector2d cell = grid_.CellCenter(ix, iy);
      const Eigen::Vector2d to = p_W - cell;
      const double distance = to.norm();
      double value = cost + 2.0 * distance;
      if (far && beyond.squaredNorm() > 0.0 && distance > 0.0) {
        const double cos_angle = std::clamp(to.dot(beyond) / distance, -1.0, 1.0);
        value += kFarLookCostPerRad * std::acos(cos_angle);
      }
      if (distance > radius_m || value >= best) continue;
      if (LaserSees(cell, p_W) && !(far && Blacklisted(cell))) {
        best = value;
        *viewpoint_W = cell;
      }
    }
  }
  return best;
}

bool Explorer::LaserSees(const Eigen::Vector2d& axle_W, const Eigen::Vector2d& p_W) const {
  // Facing the point, the laser sits laser_ahead_m_ along the line from the
  // axle to it (at the axle when the point is nearer than that).
  const Eigen::Vector2d to = p_W - axle_W;
  const double distance = to.norm();
  const Eigen::Vector2d laser_W =
      distance > laser_ahead_m_ ? Eigen::Vector2d(axle_W + laser_ahead_m_ / distance * to)
                                : axle_W;
  return (p_W - laser_W).norm() <= params_.max_insert_range_m && SeesPoint(grid_, laser_W, p_W);
}

void Explorer::ArriveAtGoal(const Pose2& X_WR, double t_s) {
  const Eigen::Vector2d axle = AxleOf(X_WR);
  const Eigen::Vector2d to = frontier_W_ - axle;
  const double error = WrapAngle(std::atan2(to.y(), to.x()) - X_WR.theta);
  const bool room = HasTurningRoom(axle);
  if (std::abs(error) > DegToRad(params_.face_frontier_deg) && room) {
    facing_ = true;
    facing_since_s_ = t_s;
    blocked_total_s_ = 0.0;
    return;
  }
  DropGoal(true, false);
}

Twist2 Explorer::FaceFrontier(const Pose2& X_WR, double t_s, double dt_s) {
  const Eigen::Vector2d to = frontier_W_ - AxleOf(X_WR);
  const double error = WrapAngle(std::atan2(to.y(), to.x()) - X_WR.theta);
  Twist2 target;
  if (std::abs(error) < DegToRad(kFacedDeg) || t_s - facing_since_s_ > kMaxFaceS ||
      blocked_total_s_ > params_.blocked_timeout_s) {
    DropGoal(true, false);
  } else {
    const double w_max = params_.max_angular_speed_radps;
    target.w_radps = std::clamp(params_.turn_gain_per_s * error, -w_max, w_max);
  }
  return RateLimit(tracker_.last_command(), target, params_.max_linear_accel_mps2 * dt_s,
                   params_.max_angular_accel_radps2 * dt_s);
}

void Explorer::ChooseGoal(const Pose2& X_WR, double t_s) {
  clearance_.Update(grid_);
  NavigationMap map(grid_, clearance_, params_, AxleOf(X_WR),
                    NavigationMap::Search::kOnDemand);
  // The scan's frontier points first, the grid's when none of those will do.
  // `unreachable` records a frontier with gain that failed or has no
  // reachable cell (a frontier only near reached goals does not count: the
  // robot went there and could not see more).
  bool unreachable = false;
  frontier_points_.clear();
  ++log_version_;
  std::vector<Candidate> candidates = ScoreFrontiers(map, local_points_, &unreachable);
  if (candidates.empty()) {
    candidates = ScoreFrontiers(map, GlobalFrontierPoints(grid_, params_), &unreachable);
  }
  // The best candidate that a path reaches; the others are blacklisted.
  // (Every candidate has a settled viewpoint, so a path is always found.)
  for (const Candidate& candidate : candidates) {
    frontier_W_ = candidate.frontier_W;
    goal_W_ = candidate.goal_W;
    has_goal_ = true;
    best_remaining_m_ = std::numeric_limits<double>::infinity();
    if (PlanToGoal(map, X_WR, t_s)) {
      blocked_total_s_ = 0.0;
      return;
    }
    DropGoal(true);
  }
  // Nothing left to explore or to reach.
  has_goal_ = false;
  finished_ = true;
  phase_ = Phase::kFinished;
  finish_reason_ = unreachable ? "unreachable" : "no_frontier";
  tracker_.Clear();
}

void Explorer::InsertScan(const Pose2& X_WR, const LaserScan& scan, const Pose2& X_RS) {
  const Pose2 X_WS = X_WR * X_RS;
  grid_.InsertScan(scan, X_WS);
  grid_.MarkRectangleFree(X_WR, params_.body_rear_x_m, params_.body_front_x_m,
                          params_.body_half_width_m);
  local_points_ = LocalFrontierPoints(scan, X_WS, params_);
  laser_ahead_m_ = std::max(0.0, a_m_ + X_RS.x);
  scan_points_W_.clear();
  for (int i = 0; i < scan.size(); ++i) {
    if (scan.has_return[i] == 0 || scan.ranges_m[i] >= scan.max_range_m) continue;
    const double th = X_WS.theta + scan.BeamAngle(i);
    scan_points_W_.push_back(X_WS.translation() +
                             scan.ranges_m[i] * Eigen::Vector2d(std::cos(th), std::sin(th)));
  }
}

Twist2 Explorer::InitialTurn(const Pose2& X_WR, double dt_s) {
  // Look around first: the laser covers only the half-plane ahead.
  if (have_last_theta_) turned_rad_ += std::abs(WrapAngle(X_WR.theta - last_theta_));
  have_last_theta_ = true;
  last_theta_ = X_WR.theta;
  if (turned_rad_ >= DegToRad(params_.initial_turn_deg)) {
    phase_ = Phase::kExploring;
    return Twist2{};
  }
  const Twist2 target{0.0, 0.5 * params_.max_angular_speed_radps};
  return RateLimit(tracker_.last_command(), target, params_.max_linear_accel_mps2 * dt_s,
                   params_.max_angular_accel_radps2 * dt_s);
}

void Explorer::CheckGoal(const Pose2& X_WR, bool new_scan, double t_s) {
  // Reached (then facing the frontier point first), explored meanwhile,
  // failed (no progress, or blocked too long).
  if (has_goal_ && tracker_.done()) ArriveAtGoal(X_WR, t_s);
  if (facing_) return;
  if (has_goal_ && new_scan &&
      !HasInformationGain(grid_, frontier_W_, params_.gain_radius_m, params_.min_gain_m2)) {
    DropGoal(false);
  }
  if (has_goal_) {
    if (t_s - progress_t_s_ > params_.progress_timeout_s ||
        blocked_total_s_ > params_.blocked_timeout_s) {
      DropGoal(true);
    }
  }
}

bool Explorer::ScanBlocksPath() const {
  const Path& path = tracker_.path();
  const double s0 = path.empty() ? 0.0 : path[tracker_.index()].s_m;
  for (int i = tracker_.index(); i < static_cast<int>(path.size()); ++i) {
    if (path[i].s_m - s0 < kPathCheckSkipM) continue;
    if (path[i].s_m - s0 > kPathCheckRangeM) break;
    for (const Eigen::Vector2d& q : scan_points_W_) {
      if ((q - path[i].p_W).norm() < params_.body_half_width_m + params_.safety_margin_m) {
        return true;
      }
    }
  }
  return false;
}

void Explorer::Replan(const Pose2& X_WR, double t_s) {
  clearance_.Update(grid_);
  // A* to the goal only: the search's cost follows the path, not the map.
  NavigationMap map(grid_, clearance_, params_, AxleOf(X_WR), NavigationMap::Search::kOnDemand);
  map.SearchTo(grid_.CellOf(goal_W_));
  if (!PlanToGoal(map, X_WR, t_s)) {
    DropGoal(true);
    ChooseGoal(X_WR, t_s);
  }
}

Twist2 Explorer::Recover(const Twist2& command, const Pose2& X_WR,
                         const std::vector<Eigen::Vector2d>& obstacles, double dt_s) {
  // Back up straight while it is safe (the occupied cells of the grid cover
  // the space behind the laser); when it is not, drive forward straight, then
  // turn in place either way, so that a robot wedged next to a door jamb
  // (where neither backing up nor the turn the path wants is safe) gets free
  // instead of failing every goal in turn. The motion chosen at the start of
  // a recovery is kept while it stays safe.
  const Twist2 escapes[] = {{-kRecoverySpeedMps, 0.0},
                            {kRecoverySpeedMps, 0.0},
                            {0.0, kRecoveryTurnRadps},
                            {0.0, -kRecoveryTurnRadps}};
  const int n = static_cast<int>(std::size(escapes));
  for (int k = 0; k < n; ++k) {
    // The current escape first, then the others in order.
    const int i = recovery_escape_ >= 0 ? (recovery_escape_ + k) % n : k;
    if (recovery_escape_ >= 0 && k > 0) break;
    bool escape_limited = false;
    const Twist2 safe = SafetyFilter(escapes[i], X_WR, obstacles, params_, a_m_, dt_s,
                                     &escape_limited);
    if (!escape_limited) {
      recovery_escape_ = i;
      return safe;
    }
  }
  // No escape is safe: the recovery ends.
  recovery_until_s_ = -1.0;
  recovery_escape_ = -1;
  return command;
}

ExplorerOutput Explorer::SafeOutput(const Twist2& wanted, const Pose2& X_WR, double t_s,
                                    double dt_s) {
  const std::vector<Eigen::Vector2d> obstacles = NearbyObstacles(X_WR);
  // A back-up recovery after the robot has been held still long enough.
  Twist2 command = wanted;
  if (blocked_s_ >= kRecoveryAfterS && recovery_until_s_ < t_s) {
    recovery_until_s_ = t_s + kRecoveryS;
    blocked_s_ = 0.0;
  }
  if (recovery_until_s_ >= t_s) {
    command = Recover(command, X_WR, obstacles, dt_s);
  } else {
    recovery_escape_ = -1;
  }
  // The safety filter, and the clocks of how long it has held the robot.
  bool limited = false;
  command = SafetyFilter(command, X_WR, obstacles, params_, a_m_, dt_s, &limited);
  tracker_.set_last_command(command);
  // Held still, or held from driving on (only a turn in place left where
  // the robot wanted to drive: at a door's jamb, a turn that never ends).
  const bool held_from_driving = std::abs(wanted.v_mps) >= 1e-3 &&
                                 std::abs(command.v_mps) < 1e-3;
  if (limited && (held_from_driving ||
                  (std::abs(command.v_mps) < 1e-3 && std::abs(command.w_radps) < 1e-3))) {
    blocked_s_ += dt_s;
    blocked_total_s_ += dt_s;
  } else {
    blocked_s_ = 0.0;
  }
  ExplorerOutput output;
  output.safety_active = limited;
  output.command = command;
  return output;
}

ExplorerOutput Explorer::Step(const Pose2& X_WR, const LaserScan* scan, const Pose2& X_RS,
                              double t_s, double dt_s) {
  MJSLAM_CHECK(dt_s > 0.0);
  // The map and the scan's frontier points.
  if (scan != nullptr) InsertScan(X_WR, *scan, X_RS);

  // The command the phase wants: the initial turn, or tracking the path to
  // the goal (kept, replaced or replanned first).
  Twist2 command;
  if (phase_ == Phase::kInitialTurn) command = InitialTurn(X_WR, dt_s);
  if (phase_ == Phase::kExploring && facing_) command = FaceFrontier(X_WR, t_s, dt_s);
  if (phase_ == Phase::kExploring && backing_out_) command = BackOut(X_WR, t_s, dt_s);
  if (phase_ == Phase::kExploring && !backing_out_ && !facing_) {
    CheckGoal(X_WR, scan != nullptr, t_s);
    if (facing_) {
      command = FaceFrontier(X_WR, t_s, dt_s);
    } else {
      if (!has_goal_) {
        ChooseGoal(X_WR, t_s);
      } else if (ScanBlocksPath() || t_s - last_plan_t_s_ >= params_.replan_period_s) {
        Replan(X_WR, t_s);
      }
      if (!finished_ && !backing_out_) command = tracker_.Command(X_WR, dt_s);
      if (!finished_ && backing_out_) command = BackOut(X_WR, t_s, dt_s);
    }
  }

  if (finished_) {
    ExplorerOutput output;
    output.finished = true;
    output.finish_reason = finish_reason_;
    output.command = Twist2{};
    return output;
  }
  // Safety layer last: it may brake harder than the acceleration limits.
  return SafeOutput(command, X_WR, t_s, dt_s);
}

}  // namespace mjslam::explorer
