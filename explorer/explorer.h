#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/laser_scan.h"
#include "common/pose2.h"
#include "common/records.h"
#include "explorer/clearance_field.h"
#include "explorer/explorer_params.h"
#include "explorer/frontiers.h"
#include "explorer/occupancy_grid.h"
#include "explorer/path_planner.h"
#include "explorer/path_tracker.h"

namespace mjslam::explorer {

/// What the explorer decided at one control step.
struct ExplorerOutput {
  /// Command for R to hold during the next `dt_s`.
  Twist2 command;
  /// True once exploration has ended (the command is then zero for good).
  bool finished = false;
  /// Why it ended: "no_frontier" (no unexplored frontier is left),
  /// "unreachable" (frontiers are left but none can be reached or all of
  /// them failed); empty while exploring.
  std::string finish_reason;
  /// Whether the safety layer changed the command at this step.
  bool safety_active = false;
};

/// One row of explorer.csv (`t,kind,index,x,y`, without the time): kind
/// "frontier" (candidate points), "goal" (one point) or "path" (points in
/// order of `index`), position in W, metres.
struct ExplorerLogRow {
  const char* kind = "";
  int index = 0;
  double x_m = 0.0;
  double y_m = 0.0;
};

/// The frontier explorer (docs/method.md, "The explorer"; the paper's ref. [10]):
/// the one entry point the application calls at every control step.
///
/// At each new scan it updates a log-odds occupancy grid at the estimated
/// laser pose and computes the scan's local frontier points. Whenever it has
/// no goal (at the start after an optional turn in place, when the goal is
/// reached, explored meanwhile, or failed), it scores the local frontier
/// points (information gain against path cost), or, when none is left, the
/// grid's global frontier points, and plans a feasible path to the best one;
/// it replans every `replan_period_s` and when the current scan blocks the
/// path. A PathTracker drives h along the path and a SafetyFilter keeps the
/// body off the walls. Goals that fail (unplannable, no progress within
/// `progress_timeout_s`, blocked by the safety layer for `blocked_timeout_s`)
/// and goals reached are blacklisted. It stops only when no frontier point
/// with gain is left ("no_frontier") or none can be reached ("unreachable").
///
/// Deterministic: no randomness, no clock; the same inputs give the same
/// outputs bit for bit.
class Explorer {
 public:
  /// `a_m` > 0: the offset of h ahead of the axle (the robot's
  /// `control_point_offset_m`), metres. Throws ParamError on invalid params
  /// (keys prefixed `explorer.`) or on a bad `a_m`.
  Explorer(const ExplorerParams& params, double a_m);

  /// One control step. `X_WR`: the pose estimate of R (the point h) in W;
  /// `scan`: a new sweep or nullptr; `X_RS`: the laser mount (pose of S in R);
  /// `t_s`: time since the start; `dt_s` > 0: how long the command will be
  /// held (the control period; checked, a broken invariant aborts). Between
  /// scans (`scan` null) it keeps using the last scan.
  ExplorerOutput Step(const Pose2& X_WR, const LaserScan* scan, const Pose2& X_RS, double t_s,
                      double dt_s);

  /// For logging (explorer.csv): the frontier points of the last goal
  /// choice (kind `frontier`), the current goal (kind `goal`), and the current
  /// path (kind `path`), in W.
  const std::vector<Eigen::Vector2d>& frontier_points() const { return frontier_points_; }
  std::optional<Eigen::Vector2d> goal() const;
  /// The frontier point the current goal views, in W (none without a goal).
  std::optional<Eigen::Vector2d> goal_frontier() const;
  const Path& path() const { return tracker_.path(); }
  /// Incremented whenever the frontier points, the goal or the path change:
  /// write explorer.csv rows when it differs from the last one written.
  int log_version() const { return log_version_; }
  /// The current set as explorer.csv rows: frontier points, the goal (if
  /// any), then the path points, each kind indexed from 0.
  std::vector<ExplorerLogRow> LogRows() const;

  /// The occupancy grid built so far.
  const OccupancyGrid& grid() const { return grid_; }
  /// A frontier point or goal cell that failed or was reached, in W.
  struct BlacklistEntry {
    Eigen::Vector2d p_W;
    bool failed = false;    ///< the goal failed (otherwise it was reached)
    bool frontier = false;  ///< a frontier point (otherwise a goal cell)
  };
  /// Frontier points and goals that failed or were reached.
  const std::vector<BlacklistEntry>& blacklist() const { return blacklist_; }
  bool finished() const { return finished_; }
  const std::string& finish_reason() const { return finish_reason_; }

 private:
  enum class Phase { kInitialTurn, kExploring, kFinished };

  // A frontier point with gain, the cell h would view it from, its score
  // (gain_weight_per_m2 * gain - cost of that cell), and its place among the
  // frontier points (ties of the score go to the earlier one).
  struct Candidate {
    Eigen::Vector2d frontier_W;
    Eigen::Vector2d goal_W;
    double score;
    int order;
    // Looked at once from a goal reached, gain left: seen again from a far
    // viewpoint away from the goals tried, once nothing else is left.
    bool second_look = false;
    // Its near viewpoint is a goal tried: only a far one will do.
    bool far_only = false;
  };

  // The steps of Step(), in order.
  // Updates the grid at X_WS = X_WR X_RS, the scan's local frontier points
  // and its echoes in W.
  void InsertScan(const Pose2& X_WR, const LaserScan& scan, const Pose2& X_RS);
  // The command of the initial turn in place; ends the turn (and returns a
  // zero command) once the robot has turned `initial_turn_deg`.
  Twist2 InitialTurn(const Pose2& X_WR, double dt_s);
  // Drops the goal when it is reached, explored meanwhile (`new_scan` only),
  // or failed (no progress within progress_timeout_s, blocked for
  // blocked_timeout_s; progress is measured at each plan, see PlanToGoal).
  void CheckGoal(const Pose2& X_WR, bool new_scan, double t_s);
  // Whether an echo of the last scan lies on the path ahead (between
  // kPathCheckSkipM and kPathCheckRangeM along it) within the body's half
  // width plus the safety margin.
  bool ScanBlocksPath() const;
  // Plans the current goal again (keeping the progress clock); when that
  // fails, drops it and chooses another.
  void Replan(const Pose2& X_WR, double t_s);
  // The safety layer: a back-up recovery when the robot has been held still,
  // the SafetyFilter, and the blocked clocks.
  ExplorerOutput SafeOutput(const Twist2& wanted, const Pose2& X_WR, double t_s, double dt_s);
  // One step of a recovery: the first safe escape motion (the current one
  // only, once chosen), or `command` when none is safe (the recovery ends).
  Twist2 Recover(const Twist2& command, const Pose2& X_WR,
                 const std::vector<Eigen::Vector2d>& obstacles, double dt_s);

  // Picks a goal (a cell for the axle) and plans a path to it; finishes when
  // there is none.
  void ChooseGoal(const Pose2& X_WR, double t_s);
  // The frontier points among `points` with gain that are not blacklisted
  // (appended to frontier_points_), scored, best first; sets `unreachable`
  // when one with gain failed before or has no reachable viewpoint. Grows
  // `map`'s search only as far as needed to know the best candidate: the
  // list holds the candidates costed by then (the best among all first).
  std::vector<Candidate> ScoreFrontiers(NavigationMap& map,
                                        const std::vector<Eigen::Vector2d>& points,
                                        bool* unreachable);
  // The least cost, path cost plus twice the distance, of a viewpoint of
  // `p_W` within `radius_m` (a reachable cell with turn_clearance_m from
  // which the laser, facing the point, sees it), and that cell's centre in
  // `viewpoint_W` (untouched when there is none: the cost is infinite).
  // `far`: cells near a blacklisted point are no viewpoints (the robot
  // looked from there), and each radian between the laser's line of sight
  // and the way into the unknown beyond the point (UnknownDirection) costs
  // kFarLookCostPerRad, so that a strip too narrow to turn in is seen along
  // its length.
  double BestViewpoint(const NavigationMap& map, const Eigen::Vector2d& p_W, double radius_m,
                       bool far, Eigen::Vector2d* viewpoint_W) const;
  // Whether the laser, with the axle at `axle_W` and the robot facing
  // `p_W`, sees `p_W` (no occupied cell between them, within range).
  bool LaserSees(const Eigen::Vector2d& axle_W, const Eigen::Vector2d& p_W) const;
  // Whether the axle at `axle_W` has turn_clearance_m (the clearance
  // brought up to date first).
  bool HasTurningRoom(const Eigen::Vector2d& axle_W);
  // Starts the turn that faces the goal's frontier point at a goal reached
  // (when it is face_frontier_deg off and the axle has turning room);
  // otherwise drops the goal as reached.
  void ArriveAtGoal(const Pose2& X_WR, double t_s);
  // One step of that turn; drops the goal as reached once the robot faces
  // the point, or when the turn is held or takes too long.
  Twist2 FaceFrontier(const Pose2& X_WR, double t_s, double dt_s);
  // Plans a path to the current goal; false when there is none. Starts a
  // back-out when the path reverses the robot's direction (a turn in place
  // of more than 90 deg first) where the axle lacks turn_clearance_m.
  bool PlanToGoal(const NavigationMap& map, const Pose2& X_WR, double t_s);
  // Starts backing out along `axle_path` (the plan from the axle): its
  // first part, to where the axle has turn_clearance_m, driven backward.
  void StartBackOut(const NavigationMap& map, const Path& axle_path, const Pose2& X_WR,
                    double t_s);
  // One step of backing out until the axle has turn_clearance_m, the part
  // is driven, the safety layer holds the robot, or it has made no progress
  // (progress_min_m along the part within progress_timeout_s); then replans
  // and returns the last command.
  Twist2 BackOut(const Pose2& X_WR, double t_s, double dt_s);
  // The robot driving backward seen as one facing back and driving forward:
  // the pose of its point h (a_m behind the axle), heading + pi.
  Pose2 FacingBack(const Pose2& X_WR) const;
  // Drops the current goal; blacklists it when `blacklist`, as failed when
  // `failed` (otherwise as reached).
  void DropGoal(bool blacklist, bool failed = true);
  // Whether a point is near a blacklisted one; `failed` (optional) tells
  // whether one of those failed, `looks` (optional) how many of those are
  // frontier points of goals reached.
  bool Blacklisted(const Eigen::Vector2d& p_W, bool* failed = nullptr,
                   int* looks = nullptr) const;
  // Obstacle points near h: the last scan's echoes and occupied cells.
  std::vector<Eigen::Vector2d> NearbyObstacles(const Pose2& X_WR) const;
  // The centre of the axle, a_m behind h: the point the planner plans for.
  Eigen::Vector2d AxleOf(const Pose2& X_WR) const;

  ExplorerParams params_;
  double a_m_;
  OccupancyGrid grid_;
  // The grid's clearance, brought up to date before each NavigationMap.
  ClearanceField clearance_;
  // The gains of frontier points scored before.
  GainCache gains_;
  PathTracker tracker_;
  Phase phase_ = Phase::kInitialTurn;

  std::vector<Eigen::Vector2d> local_points_;
  std::vector<Eigen::Vector2d> scan_points_W_;
  std::vector<Eigen::Vector2d> frontier_points_;
  std::vector<BlacklistEntry> blacklist_;

  bool has_goal_ = false;
  // The frontier point the goal serves, and the cell h drives to.
  Eigen::Vector2d frontier_W_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d goal_W_ = Eigen::Vector2d::Zero();
  double last_plan_t_s_ = 0.0;
  // The shortest axle path to the goal planned so far (each plan starts at
  // the axle), and when it last got progress_min_m shorter.
  double best_remaining_m_ = 0.0;
  double progress_t_s_ = 0.0;
  // Time the safety layer has held the robot still: in a row (triggers a
  // recovery) and in all since the goal was chosen (fails the goal).
  double blocked_s_ = 0.0;
  double blocked_total_s_ = 0.0;
  // End of the current back-up recovery, seconds (< t when none).
  double recovery_until_s_ = -1.0;
  // Index of the escape motion of the current recovery, or -1.
  int recovery_escape_ = -1;

  // Backing out of a narrow place before a path that reverses direction:
  // the tracker of the part driven backward (the path of the point a_m
  // behind the axle), the arc length backed at the last progress, and when.
  bool backing_out_ = false;
  PathTracker reverse_tracker_;
  double back_out_best_s_ = 0.0;
  double back_out_progress_t_s_ = 0.0;
  // The safety layer held the last back-out for the current goal: no new
  // one (the recovery takes over), or the two would alternate for ever.
  bool back_out_held_ = false;
  // Turning in place at a goal reached to face its frontier point, since.
  bool facing_ = false;
  double facing_since_s_ = 0.0;
  // How far the laser sits ahead of the axle (from the last scan's mount), m.
  double laser_ahead_m_ = 0.0;

  double turned_rad_ = 0.0;
  double last_theta_ = 0.0;
  bool have_last_theta_ = false;

  bool finished_ = false;
  std::string finish_reason_;
  int log_version_ = 0;
};

}  // namespace mjslam::explorer
