#pragma once

#include <vector>

#include "common/params.h"

namespace mjslam::explorer {

/// Every setting of the frontier explorer (config section `explorer`). Units
/// are in the names; frame R is the point of control h, `a` ahead of the axle
/// (the offset `a` itself is the robot's `control_point_offset_m`, passed to
/// the Explorer's constructor). The defaults suit the shipped worlds (2 m
/// corridors, 1.4 m doors) with the Pioneer 3-DX and the SICK LMS200.
struct ExplorerParams {
  // --- Occupancy grid (log-odds) ---
  /// Cell size, metres.
  double grid_resolution_m = 0.05;
  /// Echoes farther than this only clear free space up to it (no occupied
  /// cell), metres.
  double max_insert_range_m = 8.0;
  /// A beam without echo clears free space up to this distance, metres.
  double no_return_free_range_m = 4.0;
  /// Log-odds added to a cell holding an echo, and to a cell crossed by a beam.
  double log_odds_hit = 0.85;
  double log_odds_miss = -0.4;
  /// Clamp of the log-odds (keeps the grid able to change its mind).
  double log_odds_min = -4.0;
  double log_odds_max = 4.0;
  /// A cell is occupied at log-odds >= this, free at <= free_threshold,
  /// unknown in between.
  double occupied_threshold = 0.6;
  double free_threshold = -0.3;

  // --- Robot body, in frame R (x forward, y left), metres ---
  /// Front and rear edges of the body along x (h is ahead of the front edge).
  double body_front_x_m = -0.02;
  double body_rear_x_m = -0.47;
  /// Half the body width.
  double body_half_width_m = 0.19;
  /// The drive wheels' collision discs (MuJoCo spheres of the wheel radius,
  /// which reach past the body's sides): centre x in R (the axle, a behind
  /// h), centre |y|, radius. They are part of the footprint the safety layer
  /// checks. A radius of 0 leaves them out.
  double wheel_x_m = -0.2025;
  double wheel_y_m = 0.165;
  double wheel_radius_m = 0.0975;

  // --- Planning ---
  /// Smallest distance between a planned path of the axle's centre and an
  /// occupied cell, metres: the hard limit. A disc of 0.328 m about the axle
  /// holds the body in every heading (to the rear corners); 0.30 m keeps
  /// 0.8 m doors passable (about 0.4 m in their middle, less once the pose
  /// estimate smears the jambs) and leaves the rear corners in tight turns to
  /// the safety layer.
  double clearance_m = 0.30;
  /// Paths with less clearance than this pay extra cost, metres.
  double preferred_clearance_m = 0.9;
  /// Weight of that extra cost: a step at zero clearance costs (1 + weight)
  /// times its length.
  double clearance_cost_weight = 3.0;
  /// Extra weight of a step in a narrow place (a door: clearance below
  /// `clearance_m` + 0.15 m): a step at `clearance_m` costs this much more
  /// per metre, falling linearly to 0 at `clearance_m` + 0.15 m, so that a
  /// path crosses a door on its clearance ridge (its middle), not a few
  /// centimetres off it.
  double narrow_cost_weight = 10.0;
  /// Clearance of the axle needed to turn in place (the rear corners reach
  /// 0.328 m from it; with the slow safety margin and half a cell, 0.40),
  /// metres: goals (viewpoints) need it; a robot without it that must
  /// reverse its direction drives its path backward to where it has it. A value
  /// below `clearance_m` is met wherever a path may go.
  double turn_clearance_m = 0.40;
  /// Around the robot's start of a plan, cells with less clearance are
  /// allowed (to leave a tight spot), within this radius, metres.
  double escape_radius_m = 0.6;
  /// Smallest radius of the arcs that round the corners of a path, metres; a
  /// corner where no such arc fits becomes a stop-and-turn point.
  double min_turn_radius_m = 0.4;
  /// Largest corner-rounding radius tried, metres.
  double max_turn_radius_m = 1.5;
  /// Spacing of the path's points, metres.
  double path_step_m = 0.05;
  /// Replan the path to the current goal this often, seconds.
  double replan_period_s = 2.0;

  // --- Frontiers and goals ---
  /// Smallest gap between two consecutive echoes (or width of a run of open
  /// beams) that counts as an opening for the robot, metres.
  double min_opening_m = 0.9;
  /// A local frontier point is placed this far back from the opening, toward
  /// the laser, metres.
  double frontier_standoff_m = 0.4;
  /// Radius within which a frontier's information gain (unknown area visible
  /// from it) is counted, metres.
  double gain_radius_m = 1.5;
  /// A frontier with less gain is already explored, m^2.
  double min_gain_m2 = 0.4;
  /// Score of a goal = gain_weight_per_m2 * gain - path length (metres).
  double gain_weight_per_m2 = 1.0;
  /// The robot stops this close to a frontier point at the most, metres: the
  /// goal is the reachable cell within this distance of it.
  double view_distance_m = 0.8;
  /// When the whole reachable map holds no viewpoint within view_distance_m
  /// of a frontier point (a dead-end strip too narrow to turn in, seen only
  /// along its length), the goal is the cell within this distance from which
  /// the laser sees the point, metres (<= max_insert_range_m).
  double max_view_distance_m = 4.0;
  /// At a goal reached, the robot turns in place to face its frontier point
  /// when the point lies more than this off its heading and the axle has
  /// turn_clearance_m, degrees (180: never).
  double face_frontier_deg = 20.0;
  /// Global frontier clusters with fewer cells are ignored.
  int min_frontier_cells = 6;
  /// The goal is reached when h is this close to the end of the path, metres.
  double goal_tolerance_m = 0.25;
  /// A goal fails when h does not get `progress_min_m` closer to it within
  /// `progress_timeout_s`.
  double progress_timeout_s = 12.0;
  double progress_min_m = 0.3;
  /// A goal fails when the safety layer blocks the robot this long, seconds.
  double blocked_timeout_s = 6.0;
  /// Frontier points within this distance of a failed or reached goal are
  /// skipped, metres.
  double blacklist_radius_m = 0.6;
  /// Turn in place by this much before exploring (the laser sees 180 deg
  /// only), degrees; 0 skips it.
  double initial_turn_deg = 360.0;

  // --- Tracking and limits ---
  /// Speed of h along straight parts of a path, m/s.
  double cruise_speed_mps = 0.4;
  /// Speed of h where the path's clearance is `clearance_m` (a door), m/s;
  /// the limit rises linearly to `cruise_speed_mps` at
  /// `preferred_clearance_m`.
  double narrow_speed_mps = 0.1;
  /// Command limits, m/s and rad/s (below the motor limits).
  double max_linear_speed_mps = 0.6;
  double max_angular_speed_radps = 1.2;
  /// Acceleration limits of the commands, m/s^2 and rad/s^2.
  double max_linear_accel_mps2 = 0.5;
  double max_angular_accel_radps2 = 2.0;
  /// Largest centripetal acceleration on a path's arcs, m/s^2.
  double max_lateral_accel_mps2 = 0.4;
  /// Distance ahead of h's nearest path point that h is steered at, metres.
  double lookahead_m = 0.35;
  /// Bearing error above which the robot turns in place first, degrees.
  double turn_in_place_deg = 60.0;
  /// Gain of in-place turns: w = gain * heading error, 1/s.
  double turn_gain_per_s = 1.5;

  // --- Safety layer ---
  /// Extra margin around the body that the safety layer keeps free, metres.
  double safety_margin_m = 0.05;
  /// The margin of a robot at rest, metres: the margin grows linearly with the
  /// speed of the body's fastest point (|v| + 0.33 m x |w|) from this value to
  /// `safety_margin_m` at 0.3 m/s, so that a creeping robot can pass a 0.8 m
  /// door (0.1375 m a side with its wheels) on a path a few centimetres off
  /// its middle.
  double safety_margin_slow_m = 0.02;
  /// Deceleration assumed for a stop, m/s^2.
  double brake_decel_mps2 = 0.8;
  /// Obstacle points (scan echoes, occupied cells) within this distance of h
  /// are checked, metres.
  double safety_range_m = 2.0;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(grid_resolution_m));
    a->Visit(MJSLAM_NVP(max_insert_range_m));
    a->Visit(MJSLAM_NVP(no_return_free_range_m));
    a->Visit(MJSLAM_NVP(log_odds_hit));
    a->Visit(MJSLAM_NVP(log_odds_miss));
    a->Visit(MJSLAM_NVP(log_odds_min));
    a->Visit(MJSLAM_NVP(log_odds_max));
    a->Visit(MJSLAM_NVP(occupied_threshold));
    a->Visit(MJSLAM_NVP(free_threshold));
    a->Visit(MJSLAM_NVP(body_front_x_m));
    a->Visit(MJSLAM_NVP(body_rear_x_m));
    a->Visit(MJSLAM_NVP(body_half_width_m));
    a->Visit(MJSLAM_NVP(wheel_x_m));
    a->Visit(MJSLAM_NVP(wheel_y_m));
    a->Visit(MJSLAM_NVP(wheel_radius_m));
    a->Visit(MJSLAM_NVP(clearance_m));
    a->Visit(MJSLAM_NVP(preferred_clearance_m));
    a->Visit(MJSLAM_NVP(clearance_cost_weight));
    a->Visit(MJSLAM_NVP(narrow_cost_weight));
    a->Visit(MJSLAM_NVP(turn_clearance_m));
    a->Visit(MJSLAM_NVP(escape_radius_m));
    a->Visit(MJSLAM_NVP(min_turn_radius_m));
    a->Visit(MJSLAM_NVP(max_turn_radius_m));
    a->Visit(MJSLAM_NVP(path_step_m));
    a->Visit(MJSLAM_NVP(replan_period_s));
    a->Visit(MJSLAM_NVP(min_opening_m));
    a->Visit(MJSLAM_NVP(frontier_standoff_m));
    a->Visit(MJSLAM_NVP(gain_radius_m));
    a->Visit(MJSLAM_NVP(min_gain_m2));
    a->Visit(MJSLAM_NVP(gain_weight_per_m2));
    a->Visit(MJSLAM_NVP(view_distance_m));
    a->Visit(MJSLAM_NVP(max_view_distance_m));
    a->Visit(MJSLAM_NVP(face_frontier_deg));
    a->Visit(MJSLAM_NVP(min_frontier_cells));
    a->Visit(MJSLAM_NVP(goal_tolerance_m));
    a->Visit(MJSLAM_NVP(progress_timeout_s));
    a->Visit(MJSLAM_NVP(progress_min_m));
    a->Visit(MJSLAM_NVP(blocked_timeout_s));
    a->Visit(MJSLAM_NVP(blacklist_radius_m));
    a->Visit(MJSLAM_NVP(initial_turn_deg));
    a->Visit(MJSLAM_NVP(cruise_speed_mps));
    a->Visit(MJSLAM_NVP(narrow_speed_mps));
    a->Visit(MJSLAM_NVP(max_linear_speed_mps));
    a->Visit(MJSLAM_NVP(max_angular_speed_radps));
    a->Visit(MJSLAM_NVP(max_linear_accel_mps2));
    a->Visit(MJSLAM_NVP(max_angular_accel_radps2));
    a->Visit(MJSLAM_NVP(max_lateral_accel_mps2));
    a->Visit(MJSLAM_NVP(lookahead_m));
    a->Visit(MJSLAM_NVP(turn_in_place_deg));
    a->Visit(MJSLAM_NVP(turn_gain_per_s));
    a->Visit(MJSLAM_NVP(safety_margin_m));
    a->Visit(MJSLAM_NVP(safety_margin_slow_m));
    a->Visit(MJSLAM_NVP(brake_decel_mps2));
    a->Visit(MJSLAM_NVP(safety_range_m));
  }
  /// Every problem with the values (keys relative to `explorer`).
  std::vector<ParamProblem> Validate() const;
  /// Throws ParamError listing every problem, keys prefixed `explorer.`.
  void ValidateOrThrow() const;
};

}  // namespace mjslam::explorer
