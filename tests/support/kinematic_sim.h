#pragma once

// A test-only kinematic simulator for the explorer: the unicycle motion of
// the Pioneer's axle (frame R is the point h, `a` ahead of it), a laser cast
// exactly against wall segments (tests/support/walls.h), and a contact check
// of the body rectangle against the walls. No MuJoCo: the explorer is tested
// on its own.

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "common/angles.h"
#include "common/laser_scan.h"
#include "common/pose2.h"
#include "common/records.h"
#include "tests/support/walls.h"

namespace mjslam::testing {

/// The robot and its laser in a world of walls.
class KinematicSim {
 public:
  struct Config {
    double a_m = 0.2;
    /// Body rectangle in R, metres.
    double body_front_x_m = -0.02;
    double body_rear_x_m = -0.47;
    double body_half_width_m = 0.19;
    /// Laser mount and beams.
    Pose2 X_RS = Pose2(-0.1, 0.0, 0.0);
    int num_beams = 181;
    double fov_deg = 180.0;
    double max_range_m = 4.0;
  };

  KinematicSim(std::vector<Wall> walls, const Pose2& X_WR0, const Config& config)
      : walls_(std::move(walls)), config_(config), X_WA_(X_WR0 * Pose2(-config.a_m, 0, 0)) {}

  /// Pose of R (the point h).
  Pose2 X_WR() const { return X_WA_ * Pose2(config_.a_m, 0.0, 0.0); }

  /// Holds `command` for `dt_s`, integrating in small substeps and
  /// recording any contact of the body with a wall.
  void Step(const Twist2& command, double dt_s) {
    const int substeps = std::max(1, static_cast<int>(std::ceil(dt_s / 0.01)));
    const double h = dt_s / substeps;
    for (int k = 0; k < substeps; ++k) {
      const double th = X_WA_.theta + 0.5 * command.w_radps * h;
      X_WA_ = Pose2(X_WA_.x + command.v_mps * h * std::cos(th),
                    X_WA_.y + command.v_mps * h * std::sin(th),
                    X_WA_.theta + command.w_radps * h);
      distance_m_ += std::abs(command.v_mps) * h;
      if (Touches()) ++contacts_;
    }
  }

  /// Whether the body overlaps a wall now.
  bool Touches() const {
    const Pose2 X_RW = X_WR().Inverse();
    for (const Wall& wall : walls_) {
      if (SegmentMeetsRectangle(X_RW * wall.a, X_RW * wall.b, config_.body_rear_x_m,
                                config_.body_front_x_m, config_.body_half_width_m)) {
        return true;
      }
    }
    return false;
  }

  /// An exact scan from the current pose (no-return beams report max range).
  LaserScan Scan(double t_s) const {
    LaserScan scan;
    scan.t_s = t_s;
    const double fov = DegToRad(config_.fov_deg);
    scan.angle_min_rad = -0.5 * fov;
    scan.angle_increment_rad = fov / (config_.num_beams - 1);
    scan.max_range_m = config_.max_range_m;
    const Pose2 X_WS = X_WR() * config_.X_RS;
    for (int i = 0; i < config_.num_beams; ++i) {
      const double th = X_WS.theta + scan.BeamAngle(i);
      const double range =
          CastRay(walls_, X_WS.translation(), Eigen::Vector2d(std::cos(th), std::sin(th)));
      const bool echo = range < config_.max_range_m;
      scan.ranges_m.push_back(echo ? range : config_.max_range_m);
      scan.has_return.push_back(echo ? 1 : 0);
    }
    return scan;
  }

  const Config& config() const { return config_; }
  int contacts() const { return contacts_; }
  double distance_m() const { return distance_m_; }

 private:
  std::vector<Wall> walls_;
  Config config_;
  Pose2 X_WA_;
  int contacts_ = 0;
  double distance_m_ = 0.0;
};

}  // namespace mjslam::testing
