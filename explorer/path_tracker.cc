#include "explorer/path_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/angles.h"
#include "common/check.h"
#include "explorer/point_h_controller.h"

namespace mjslam::explorer {
namespace {

// Slowest reference speed while driving along a path, m/s: keeps the robot
// from creeping forever toward a stop point.
constexpr double kMinDriveSpeedMps = 0.08;
// A stop-and-turn point is reached when h is this close, metres.
constexpr double kTurnPointToleranceM = 0.1;
// ... or when h is this close and the point is not ahead, metres.
constexpr double kTurnPointNearM = 0.3;
// An in-place turn is finished within this heading error, radians.
constexpr double kTurnDoneRad = 0.1;
// How far ahead of the last nearest point h's nearest point is searched, m.
constexpr double kSearchWindowM = 1.5;
// The wheels reach a new command with a lag (MuJoCo's torque-driven wheels:
// about 0.03 s in the office runs); the safety layer predicts each command held
// this much longer than the control period, seconds.
constexpr double kWheelLagS = 0.05;
// The body's farthest point from the axle (a rear corner), metres: its speed
// in a turn is this times |w|.
constexpr double kBodyReachM = 0.33;
// Speed of the body's fastest point at which the safety margin is whole, m/s.
constexpr double kFullMarginSpeedMps = 0.3;
// A robot within a command's safety margin may make it when no point of the
// predicted motion comes closer than this less than its clearance now, m.
constexpr double kNoCloserM = 1e-4;

}  // namespace

PathTracker::PathTracker(const ExplorerParams& params, double a_m)
    : params_(params), a_m_(a_m) {
  MJSLAM_CHECK(a_m_ > 0.0);
}

void PathTracker::SetPath(Path path) {
  path_ = std::move(path);
  index_ = 0;
  turning_at_ = -1;
  done_ = path_.empty();
}

void PathTracker::Clear() { SetPath({}); }

Twist2 PathTracker::Command(const Pose2& X_WR, double dt_s) {
  const Eigen::Vector2d h = X_WR.translation();
  Twist2 desired;
  if (!path_.empty() && !done_) {
    const int n = static_cast<int>(path_.size());
    // Nearest point, forward from the last one, not past a pending
    // stop-and-turn point.
    int limit = index_;
    while (limit + 1 < n && path_[limit + 1].s_m - path_[index_].s_m < kSearchWindowM &&
           !(path_[limit].turn_in_place && limit != turning_at_ && limit > index_)) {
      ++limit;
    }
    int best = index_;
    for (int i = index_; i <= limit; ++i) {
      if ((path_[i].p_W - h).squaredNorm() < (path_[best].p_W - h).squaredNorm()) best = i;
    }
    index_ = best;
    if ((path_.back().p_W - h).norm() < params_.goal_tolerance_m &&
        path_.back().s_m - path_[index_].s_m < 2.0 * params_.goal_tolerance_m) {
      done_ = true;
    }
    // The next stop-and-turn point at or after the nearest one.
    int stop = index_;
    while (stop < n - 1 && !path_[stop].turn_in_place) ++stop;
    // It is reached when h is close, or near and no longer ahead (h passed
    // beside it: steering at it would only turn the robot in place, about
    // the axle, around it).
    if (!done_ && path_[stop].turn_in_place && turning_at_ != stop) {
      const Eigen::Vector2d to_stop = path_[stop].p_W - h;
      const double bearing = WrapAngle(std::atan2(to_stop.y(), to_stop.x()) - X_WR.theta);
      if (to_stop.norm() < kTurnPointToleranceM ||
          (to_stop.norm() < kTurnPointNearM &&
           std::abs(bearing) > DegToRad(params_.turn_in_place_deg))) {
        turning_at_ = stop;
      }
    }
    if (done_) {
      // Brake.
    } else if (turning_at_ >= 0) {
      // Turning in place at a stop point.
      const double error = WrapAngle(path_[turning_at_].heading_rad - X_WR.theta);
      if (std::abs(error) < kTurnDoneRad) {
        // A stop point is passed once: clear its flag and move past it.
        path_[turning_at_].turn_in_place = false;
        index_ = std::min(n - 1, turning_at_ + 1);
        turning_at_ = -1;
      } else {
        desired.w_radps = params_.turn_gain_per_s * error;
      }
    }
    if (!done_ && turning_at_ < 0) {
      // Steering point: lookahead along the path, not past the next stop.
      int carrot = index_;
      while (carrot < n - 1 && carrot < stop &&
             path_[carrot].s_m - path_[index_].s_m < params_.lookahead_m) {
        ++carrot;
      }
      Eigen::Vector2d to_carrot = path_[carrot].p_W - h;
      double distance = to_carrot.norm();
      if (distance < 1e-6) {
        to_carrot = Eigen::Vector2d(std::cos(path_[carrot].heading_rad),
                                    std::sin(path_[carrot].heading_rad));
        distance = 1e-6;
      }
      const double bearing =
          WrapAngle(std::atan2(to_carrot.y(), to_carrot.x()) - X_WR.theta);
      if (std::abs(bearing) > DegToRad(params_.turn_in_place_deg)) {
        desired.w_radps = params_.turn_gain_per_s * bearing;
      } else {
        double speed = std::max(path_[index_].speed_mps, kMinDriveSpeedMps);
        // Toward a stop or the end: no faster than braking allows.
        const double to_stop = (path_[stop].p_W - h).norm();
        speed = std::min(speed, std::max(kMinDriveSpeedMps,
                                         std::sqrt(2.0 * params_.max_linear_accel_mps2 *
                                                   to_stop)));
        desired = CommandForPointVelocity(X_WR, speed * to_carrot / to_carrot.norm(), a_m_);
      }
    }
  }
  desired = SaturateKeepingCurvature(desired, params_.max_linear_speed_mps,
                                     params_.max_angular_speed_radps);
  last_ = RateLimit(last_, desired, params_.max_linear_accel_mps2 * dt_s,
                    params_.max_angular_accel_radps2 * dt_s);
  return last_;
}

bool BodyTouches(const Pose2& X_WR, const std::vector<Eigen::Vector2d>& points_W,
                 const ExplorerParams& params, double margin_m) {
  const Pose2 X_RW = X_WR.Inverse();
  const bool wheels = params.wheel_radius_m > 0.0;
  const double wheel_reach = params.wheel_radius_m + margin_m;
  for (const Eigen::Vector2d& p_W : points_W) {
    const Eigen::Vector2d p_R = X_RW * p_W;
    if (p_R.x() >= params.body_rear_x_m - margin_m &&
        p_R.x() <= params.body_front_x_m + margin_m &&
        std::abs(p_R.y()) <= params.body_half_width_m + margin_m) {
      return true;
    }
    // The wheels' collision discs reach past the body's sides.
    if (wheels && Eigen::Vector2d(p_R.x() - params.wheel_x_m, std::abs(p_R.y()) - params.wheel_y_m)
                          .squaredNorm() <= wheel_reach * wheel_reach) {
      return true;
    }
  }
  return false;
}

double BodyClearanceM(const Pose2& X_WR, const std::vector<Eigen::Vector2d>& points_W,
                      const ExplorerParams& params) {
  const Pose2 X_RW = X_WR.Inverse();
  const bool wheels = params.wheel_radius_m > 0.0;
  double clearance = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector2d& p_W : points_W) {
    const Eigen::Vector2d p_R = X_RW * p_W;
    // The rectangle grown by m holds p when the larger of its distances
    // outside the rectangle along x and along y is at most m.
    const double outside_x = std::max({params.body_rear_x_m - p_R.x(),
                                       p_R.x() - params.body_front_x_m, 0.0});
    const double outside_y = std::max(std::abs(p_R.y()) - params.body_half_width_m, 0.0);
    clearance = std::min(clearance, std::max(outside_x, outside_y));
    if (wheels) {
      const double to_wheel =
          Eigen::Vector2d(p_R.x() - params.wheel_x_m, std::abs(p_R.y()) - params.wheel_y_m).norm();
      clearance = std::min(clearance, std::max(0.0, to_wheel - params.wheel_radius_m));
    }
  }
  return clearance;
}

namespace {

// Whether the body touches an obstacle while `command` is held for `dt_s`
// and then braked to a stop, integrating the axle's unicycle motion.
bool PredictedContact(const Twist2& command, const Pose2& X_WR,
                      const std::vector<Eigen::Vector2d>& obstacles_W,
                      const ExplorerParams& params, double a_m, double dt_s,
                      double margin_m) {
  // Only obstacles the body could reach matter.
  std::vector<Eigen::Vector2d> near;
  const double reach = params.safety_range_m;
  for (const Eigen::Vector2d& q : obstacles_W) {
    if ((q - X_WR.translation()).squaredNorm() < reach * reach) near.push_back(q);
  }
  if (near.empty()) return false;
  // The wheels follow a new command with a lag: the command acts for about
  // kWheelLagS longer than it is held before the brake takes effect.
  const double hold = dt_s + kWheelLagS;
  const double brake_time = std::abs(command.v_mps) / params.brake_decel_mps2;
  const double horizon = hold + brake_time;
  const double step = 0.05;
  const int n = std::max(1, static_cast<int>(std::ceil(horizon / step)));
  // Pose of the axle A (a behind h).
  Pose2 X_WA = X_WR * Pose2(-a_m, 0.0, 0.0);
  const Pose2 X_AR(a_m, 0.0, 0.0);
  for (int k = 0; k <= n; ++k) {
    const double t = k * horizon / n;
    if (BodyTouches(X_WA * X_AR, near, params, margin_m)) return true;
    // Speed scale: 1 while held, then linear braking.
    const double scale =
        t < hold ? 1.0 : std::max(0.0, 1.0 - (t - hold) / std::max(brake_time, 1e-9));
    const double h = horizon / n;
    const double v = scale * command.v_mps;
    const double w = scale * command.w_radps;
    X_WA = Pose2(X_WA.x + v * h * std::cos(X_WA.theta + 0.5 * w * h),
                 X_WA.y + v * h * std::sin(X_WA.theta + 0.5 * w * h), X_WA.theta + w * h);
  }
  return false;
}

}  // namespace

double SafetyMarginM(const Twist2& command, const ExplorerParams& params) {
  const double speed = std::abs(command.v_mps) + kBodyReachM * std::abs(command.w_radps);
  const double fraction = std::min(1.0, speed / kFullMarginSpeedMps);
  return params.safety_margin_slow_m +
         fraction * (params.safety_margin_m - params.safety_margin_slow_m);
}

Twist2 SafetyFilter(const Twist2& command, const Pose2& X_WR,
                    const std::vector<Eigen::Vector2d>& obstacles_W,
                    const ExplorerParams& params, double a_m, double dt_s, bool* limited) {
  // A robot already inside the slow margin may still move (away). One
  // between the slow margin and a command's margin may make the motions that
  // come no closer than it is: without that, every command but a stop touched
  // at once, and a robot stopped with a wheel 0.025 m from a door's jamb
  // stood there until no goal was left.
  const double clearance = BodyClearanceM(X_WR, obstacles_W, params);
  const bool inside = clearance <= params.safety_margin_slow_m;
  const Twist2 candidates[] = {command,
                               {0.5 * command.v_mps, command.w_radps},
                               {command.v_mps, 0.0},
                               {0.5 * command.v_mps, 0.0},
                               {0.0, command.w_radps},
                               {0.0, 0.0}};
  if (limited != nullptr) *limited = false;
  for (const Twist2& candidate : candidates) {
    const double margin =
        inside ? 0.0
               : std::min(SafetyMarginM(candidate, params), clearance - kNoCloserM);
    if (!PredictedContact(candidate, X_WR, obstacles_W, params, a_m, dt_s, margin)) {
      if (limited != nullptr) {
        *limited = candidate.v_mps != command.v_mps || candidate.w_radps != command.w_radps;
      }
      return candidate;
    }
  }
  if (limited != nullptr) *limited = command.v_mps != 0.0 || command.w_radps != 0.0;
  return {0.0, 0.0};
}

}  // namespace mjslam::explorer
