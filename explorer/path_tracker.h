#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/pose2.h"
#include "common/records.h"
#include "explorer/explorer_params.h"
#include "explorer/path_planner.h"

namespace mjslam::explorer {

/// Follows a Path with the point h. At every step it finds the path point
/// nearest to h (searching forward from the last one, so the path is never
/// followed backward), steers h at the point `lookahead_m` further along
/// (not past the next stop-and-turn point) at the path's reference speed,
/// through the inverted kinematics of h (CommandForPointVelocity, the
/// paper's Eq. (6)); turns in place at stop-and-turn points and whenever the
/// steering point lies more than `turn_in_place_deg` off the heading; then
/// saturates keeping the curvature and limits the accelerations.
class PathTracker {
 public:
  /// `a_m` > 0: the offset of h ahead of the axle, metres.
  PathTracker(const ExplorerParams& params, double a_m);

  /// Starts following `path` (keeps the last command for the rate limits).
  void SetPath(Path path);
  /// Drops the path; the next commands brake to a stop.
  void Clear();
  /// The command for the next `dt_s` seconds given the pose of R.
  Twist2 Command(const Pose2& X_WR, double dt_s);

  /// Whether h has reached the end of the path (within `goal_tolerance_m`).
  bool done() const { return done_; }
  const Path& path() const { return path_; }
  /// Index of the path point nearest to h.
  int index() const { return index_; }
  /// The last command returned (after saturation and rate limits).
  const Twist2& last_command() const { return last_; }
  /// Overrides the last command (after the safety layer changed it).
  void set_last_command(const Twist2& command) { last_ = command; }

 private:
  ExplorerParams params_;
  double a_m_;
  Path path_;
  int index_ = 0;
  // Index of the stop-and-turn point being executed, or -1.
  int turning_at_ = -1;
  bool done_ = false;
  Twist2 last_;
};

/// The safety margin for a command, metres: `safety_margin_slow_m` at rest,
/// growing linearly with the speed of the body's fastest point (|v| + 0.33 m
/// x |w|) to `safety_margin_m` at 0.3 m/s.
double SafetyMarginM(const Twist2& command, const ExplorerParams& params);

/// The safety layer. Predicts the body of the robot (the rectangle of
/// ExplorerParams' body_* fields and the wheel discs, grown by the margin
/// SafetyMarginM gives each command tried) under `command`
/// held for `dt_s` and then braking at `brake_decel_mps2` (the yaw rate
/// braking in proportion), and checks it against `obstacles_W` (scan echoes
/// and occupied cells near the robot). When the prediction touches an
/// obstacle it tries, in order, half the speed, no turn, half the speed and
/// no turn, turning in place, a full stop. When the body is already within
/// the slow margin of an obstacle,
/// only actual contact is checked, so the robot can still move away; when it
/// is within a command's margin but not the slow one, the command may come no
/// closer than the body is now (`BodyClearanceM`).
/// `a_m` is the offset of h ahead of the axle; `limited` (optional) tells
/// whether the command was changed.
Twist2 SafetyFilter(const Twist2& command, const Pose2& X_WR,
                    const std::vector<Eigen::Vector2d>& obstacles_W,
                    const ExplorerParams& params, double a_m, double dt_s, bool* limited);

/// The margin by which the body of the robot at `X_WR` clears the nearest
/// of `points_W` (infinity for none): `BodyTouches(X_WR, points_W, params, m)`
/// is true exactly when this is at most m (the rectangle's margin measured
/// along its axes, the wheel discs' radially).
double BodyClearanceM(const Pose2& X_WR, const std::vector<Eigen::Vector2d>& points_W,
                      const ExplorerParams& params);

/// Whether any of `points_W` lies inside the body rectangle of the robot at
/// `X_WR`, grown by `margin_m`.
bool BodyTouches(const Pose2& X_WR, const std::vector<Eigen::Vector2d>& points_W,
                 const ExplorerParams& params, double margin_m);

}  // namespace mjslam::explorer
