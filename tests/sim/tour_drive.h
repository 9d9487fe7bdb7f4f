#pragma once

// Driving a world's tour in tests: the tour's length, and a simple point-h
// controller that drives it while checking for contacts.

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "sim/simulator.h"

namespace mjslam::sim::testing {

/// Length of the closed tour through `tour`, metres.
inline double TourLength(const std::vector<Eigen::Vector2d>& tour) {
  double length = 0.0;
  for (std::size_t i = 0; i < tour.size(); ++i) {
    length += (tour[(i + 1) % tour.size()] - tour[i]).norm();
  }
  return length;
}

/// Drives the tour once with a proportional controller on the point h (the
/// offset a makes its kinematics invertible, Eq. (6)), checking for contacts
/// every 0.1 s, until the tour is closed or h has driven `max_driven_m`.
/// Fails as stuck when no waypoint is reached within 60 s plus the time the
/// leg needs at `speed_mps`. Returns the distance driven by h.
inline double DriveTour(Simulator* sim, double speed_mps,
                        double max_driven_m = std::numeric_limits<double>::infinity()) {
  const std::vector<Eigen::Vector2d>& tour = sim->scene().TourWaypoints();
  const double a = sim->robot().control_point_offset_m;
  std::size_t target = 1;
  std::size_t reached = 0;
  double driven = 0.0;
  Eigen::Vector2d last = sim->X_WR().translation();
  double last_progress_s = 0.0;
  while (reached < tour.size() && driven < max_driven_m) {
    const Pose2 X_WR = sim->X_WR();
    const Eigen::Vector2d error = tour[target % tour.size()] - X_WR.translation();
    if (error.norm() < 0.25) {
      ++reached;
      ++target;
      last_progress_s = sim->time_s();
      continue;
    }
    // Desired velocity of h, then (v, w) from the inverse of Eq. (6).
    const Eigen::Vector2d velocity = error.normalized() * std::min(speed_mps, 1.5 * error.norm());
    const double c = std::cos(X_WR.theta);
    const double s = std::sin(X_WR.theta);
    sim->SetCommand(
        {c * velocity.x() + s * velocity.y(), (-s * velocity.x() + c * velocity.y()) / a});
    sim->Advance(0.1);
    driven += (sim->X_WR().translation() - last).norm();
    last = sim->X_WR().translation();
    EXPECT_EQ(sim->CountRobotWorldContacts(), 0)
        << "contact at t = " << sim->time_s() << " s near tour_" << target % tour.size();
    const double leg_s = (tour[target % tour.size()] - tour[(target - 1) % tour.size()]).norm() /
                         speed_mps;
    if (sim->CountRobotWorldContacts() > 0 || sim->time_s() - last_progress_s > 60.0 + leg_s) {
      ADD_FAILURE() << "stuck before tour_" << target % tour.size();
      break;
    }
  }
  return driven;
}

}  // namespace mjslam::sim::testing
