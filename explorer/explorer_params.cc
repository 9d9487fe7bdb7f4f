#include "explorer/explorer_params.h"

namespace mjslam::explorer {

std::vector<ParamProblem> ExplorerParams::Validate() const {
  ParamChecker check;
  check.InRange("grid_resolution_m", grid_resolution_m, 0.01, 0.5);
  check.Positive("max_insert_range_m", max_insert_range_m);
  check.Positive("no_return_free_range_m", no_return_free_range_m);
  check.Positive("log_odds_hit", log_odds_hit);
  check.Require(log_odds_miss < 0.0, "log_odds_miss", log_odds_miss, "a value < 0");
  check.Require(log_odds_min < 0.0, "log_odds_min", log_odds_min, "a value < 0");
  check.Positive("log_odds_max", log_odds_max);
  check.Require(occupied_threshold > 0.0 && occupied_threshold <= log_odds_max,
                "occupied_threshold", occupied_threshold, "a value in (0, log_odds_max]");
  check.Require(free_threshold < 0.0 && free_threshold >= log_odds_min, "free_threshold",
                free_threshold, "a value in [log_odds_min, 0)");
  check.Require(body_front_x_m > body_rear_x_m, "body_front_x_m", body_front_x_m,
                "a value > body_rear_x_m");
  check.Positive("body_half_width_m", body_half_width_m);
  check.NonNegative("wheel_y_m", wheel_y_m);
  check.NonNegative("wheel_radius_m", wheel_radius_m);
  check.Require(clearance_m >= body_half_width_m, "clearance_m", clearance_m,
                "a value >= body_half_width_m");
  check.Require(preferred_clearance_m >= clearance_m, "preferred_clearance_m",
                preferred_clearance_m, "a value >= clearance_m");
  check.NonNegative("clearance_cost_weight", clearance_cost_weight);
  check.NonNegative("narrow_cost_weight", narrow_cost_weight);
  // Below clearance_m it is simply met wherever a path may go (every cell a
  // plan uses has clearance_m), so a config with a large clearance_m (such
  // as the 0.5 m of run directories made before this key existed) stays
  // valid.
  check.Positive("turn_clearance_m", turn_clearance_m);
  check.NonNegative("escape_radius_m", escape_radius_m);
  check.Positive("min_turn_radius_m", min_turn_radius_m);
  check.Require(max_turn_radius_m >= min_turn_radius_m, "max_turn_radius_m",
                max_turn_radius_m, "a value >= min_turn_radius_m");
  check.Require(path_step_m > 0.0 && path_step_m <= 0.5, "path_step_m", path_step_m,
                "a value in (0, 0.5]");
  check.Positive("replan_period_s", replan_period_s);
  check.Positive("min_opening_m", min_opening_m);
  check.NonNegative("frontier_standoff_m", frontier_standoff_m);
  check.Positive("gain_radius_m", gain_radius_m);
  check.NonNegative("min_gain_m2", min_gain_m2);
  check.NonNegative("gain_weight_per_m2", gain_weight_per_m2);
  check.Positive("view_distance_m", view_distance_m);
  check.Require(max_view_distance_m >= view_distance_m &&
                    max_view_distance_m <= max_insert_range_m,
                "max_view_distance_m", max_view_distance_m,
                "a value in [view_distance_m, max_insert_range_m]");
  check.Require(face_frontier_deg > 0.0 && face_frontier_deg <= 180.0, "face_frontier_deg",
                face_frontier_deg, "a value in (0, 180]");
  check.Require(min_frontier_cells >= 1, "min_frontier_cells", min_frontier_cells,
                "a value >= 1");
  check.Positive("goal_tolerance_m", goal_tolerance_m);
  check.Positive("progress_timeout_s", progress_timeout_s);
  check.Positive("progress_min_m", progress_min_m);
  check.Positive("blocked_timeout_s", blocked_timeout_s);
  check.NonNegative("blacklist_radius_m", blacklist_radius_m);
  check.InRange("initial_turn_deg", initial_turn_deg, 0.0, 720.0);
  check.Positive("cruise_speed_mps", cruise_speed_mps);
  check.Positive("narrow_speed_mps", narrow_speed_mps);
  check.Require(narrow_speed_mps <= cruise_speed_mps, "narrow_speed_mps", narrow_speed_mps,
                "at most cruise_speed_mps");
  check.Positive("max_linear_speed_mps", max_linear_speed_mps);
  check.Require(cruise_speed_mps <= max_linear_speed_mps, "cruise_speed_mps",
                cruise_speed_mps, "at most max_linear_speed_mps");
  check.Positive("max_angular_speed_radps", max_angular_speed_radps);
  check.Positive("max_linear_accel_mps2", max_linear_accel_mps2);
  check.Positive("max_angular_accel_radps2", max_angular_accel_radps2);
  check.Positive("max_lateral_accel_mps2", max_lateral_accel_mps2);
  check.Positive("lookahead_m", lookahead_m);
  check.InRange("turn_in_place_deg", turn_in_place_deg, 1.0, 180.0);
  check.Positive("turn_gain_per_s", turn_gain_per_s);
  check.NonNegative("safety_margin_m", safety_margin_m);
  check.Require(safety_margin_slow_m >= 0.0 && safety_margin_slow_m <= safety_margin_m,
                "safety_margin_slow_m", safety_margin_slow_m, "a value in [0, safety_margin_m]");
  check.Positive("brake_decel_mps2", brake_decel_mps2);
  check.Positive("safety_range_m", safety_range_m);
  return check.problems();
}

void ExplorerParams::ValidateOrThrow() const {
  ParamChecker check;
  check.Merge("explorer", Validate());
  ThrowIfProblems(check.problems());
}

}  // namespace mjslam::explorer
