#pragma once

// A tiny synthetic world of walls and corners for the filter's tests and
// benchmarks: observations are computed from the true geometry (not from the
// filter's models) and optionally perturbed with Gaussian noise.

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "common/angles.h"
#include "common/pose2.h"
#include "common/rng.h"
#include "slam/observations.h"
#include "tests/support/walls.h"

namespace mjslam::testing {

/// Walls and corners in W.
struct SyntheticWorld {
  std::vector<Wall> walls;
  std::vector<Eigen::Vector2d> corners;
};

/// How observations are made.
struct ObservationNoise {
  double rho_std_m = 0.01;
  double alpha_std_rad = 0.005;
  double range_std_m = 0.02;
  double bearing_std_rad = 0.005;
  /// Covariances reported to the filter are the true ones times this (1:
  /// honest; 0.01: standard deviations understated 10x).
  double reported_variance_scale = 1.0;
  /// Features farther than this are not seen, metres.
  double max_range_m = 8.0;
};

/// A rectangular room [0, width] x [0, height] with a rectangular pillar
/// [x0, x1] x [y0, y1] inside: 8 walls, 8 corners (4 concave, 4 convex).
inline SyntheticWorld RoomWithPillar(double width, double height, double x0, double y0,
                                     double x1, double y1) {
  SyntheticWorld world;
  const auto add_box = [&world](double ax, double ay, double bx, double by) {
    const Eigen::Vector2d p00(ax, ay), p10(bx, ay), p11(bx, by), p01(ax, by);
    world.walls.push_back({p00, p10});
    world.walls.push_back({p10, p11});
    world.walls.push_back({p11, p01});
    world.walls.push_back({p01, p00});
    for (const Eigen::Vector2d& p : {p00, p10, p11, p01}) world.corners.push_back(p);
  };
  add_box(0.0, 0.0, width, height);
  add_box(x0, y0, x1, y1);
  return world;
}

/// The features of `world` seen from the sensor pose X_WS: every corner in
/// front of the sensor (x_S > 0.1) within range, and every wall with a part in
/// front within range (the part in front, clipped, gives the endpoints).
/// Occlusion is ignored. With `rng` null the observations are exact.
inline slam::ScanFeatures ObserveWorld(const SyntheticWorld& world, const Pose2& X_WS,
                                 const ObservationNoise& noise, Rng* rng) {
  const Pose2 X_SW = X_WS.Inverse();
  const auto draw = [rng](double std) { return rng == nullptr ? 0.0 : rng->Gaussian(0.0, std); };
  slam::ScanFeatures features;
  for (const Wall& wall : world.walls) {
    Eigen::Vector2d p_SA = X_SW * wall.a;
    Eigen::Vector2d p_SB = X_SW * wall.b;
    // Clip to the half-plane x_S >= 0.1 in front of the sensor.
    constexpr double kFront = 0.1;
    if (p_SA.x() < kFront && p_SB.x() < kFront) continue;
    if (p_SA.x() < kFront) p_SA = p_SB + (p_SA - p_SB) * (p_SB.x() - kFront) / (p_SB.x() - p_SA.x());
    if (p_SB.x() < kFront) p_SB = p_SA + (p_SB - p_SA) * (p_SA.x() - kFront) / (p_SA.x() - p_SB.x());
    if (std::min(p_SA.norm(), p_SB.norm()) > noise.max_range_m) continue;
    // The line through the two points, in polar form with rho >= 0.
    const Eigen::Vector2d polar = PolarLineThrough(p_SA, p_SB);
    slam::LineObservation line;
    line.rho_m = polar[0] + draw(noise.rho_std_m);
    line.alpha_rad = WrapAngle(polar[1] + draw(noise.alpha_std_rad));
    if (line.rho_m < 0.0) {
      line.rho_m = -line.rho_m;
      line.alpha_rad = WrapAngle(line.alpha_rad + kPi);
    }
    line.covariance = noise.reported_variance_scale *
                      Eigen::Vector2d(noise.rho_std_m * noise.rho_std_m,
                                      noise.alpha_std_rad * noise.alpha_std_rad)
                          .asDiagonal();
    line.p_SA = p_SA;
    line.p_SB = p_SB;
    features.lines.push_back(line);
  }
  for (const Eigen::Vector2d& p_WC : world.corners) {
    const Eigen::Vector2d p_SC = X_SW * p_WC;
    if (p_SC.x() < 0.1 || p_SC.norm() > noise.max_range_m) continue;
    slam::CornerObservation corner;
    corner.range_m = p_SC.norm() + draw(noise.range_std_m);
    corner.bearing_rad = WrapAngle(std::atan2(p_SC.y(), p_SC.x()) + draw(noise.bearing_std_rad));
    corner.covariance = noise.reported_variance_scale *
                        Eigen::Vector2d(noise.range_std_m * noise.range_std_m,
                                        noise.bearing_std_rad * noise.bearing_std_rad)
                            .asDiagonal();
    corner.p_SC = corner.range_m * Eigen::Vector2d(std::cos(corner.bearing_rad),
                                                   std::sin(corner.bearing_rad));
    features.corners.push_back(corner);
  }
  return features;
}

}  // namespace mjslam::testing
