#include <cmath>

#include <gtest/gtest.h>

#include "explorer/waypoint_driver.h"

namespace mjslam::explorer {
namespace {

// Integrates the paper's Eq. (6) for one step.
Pose2 Integrate(const Pose2& X, const Twist2& u, double a, double dt) {
  return Pose2(X.x + dt * (u.v_mps * std::cos(X.theta) - a * u.w_radps * std::sin(X.theta)),
               X.y + dt * (u.v_mps * std::sin(X.theta) + a * u.w_radps * std::cos(X.theta)),
               X.theta + dt * u.w_radps);
}

TEST(WaypointDriverTest, VisitsEveryWaypointInOrderWithinLimits) {
  WaypointDriverParams params;
  params.loop = false;
  const double a = 0.2;
  const double dt = 0.1;
  // A square tour that starts facing away from the first waypoint.
  const std::vector<Eigen::Vector2d> tour = {{2, 0}, {2, 2}, {0, 2}, {0, 0}};
  WaypointDriver driver(params, tour, a);
  Pose2 X(0.0, 0.0, 3.0);
  int max_index = 0;
  Twist2 previous;
  for (int step = 0; step < 1000 && !driver.finished(); ++step) {
    const Twist2 u = driver.Command(X, dt);
    EXPECT_LE(std::abs(u.v_mps), params.max_linear_speed_mps + 1e-12);
    EXPECT_LE(std::abs(u.w_radps), params.max_angular_speed_radps + 1e-12);
    EXPECT_LE(std::abs(u.v_mps - previous.v_mps), params.max_linear_accel_mps2 * dt + 1e-12);
    EXPECT_LE(std::abs(u.w_radps - previous.w_radps),
              params.max_angular_accel_radps2 * dt + 1e-12);
    EXPECT_GE(driver.target_index(), max_index);  // never goes back
    max_index = driver.target_index();
    previous = u;
    X = Integrate(X, u, a, dt);
  }
  EXPECT_TRUE(driver.finished());
  EXPECT_LT((X.translation() - tour.back()).norm(), params.waypoint_tolerance_m + 0.05);
}

TEST(WaypointDriverTest, LoopsBackToTheFirstWaypoint) {
  WaypointDriverParams params;
  const std::vector<Eigen::Vector2d> tour = {{1, 0}, {1, 1}};
  WaypointDriver driver(params, tour, 0.2);
  Pose2 X(0.0, 0.0, 0.0);
  bool wrapped = false;
  int last = 0;
  for (int step = 0; step < 600; ++step) {
    X = Integrate(X, driver.Command(X, 0.1), 0.2, 0.1);
    if (last == 1 && driver.target_index() == 0) wrapped = true;
    last = driver.target_index();
  }
  EXPECT_TRUE(wrapped);
  EXPECT_FALSE(driver.finished());
}

TEST(WaypointDriverTest, RejectsEmptyTourAndBadParams) {
  EXPECT_THROW(WaypointDriver(WaypointDriverParams{}, {}, 0.2), ParamError);
  WaypointDriverParams bad;
  bad.cruise_speed_mps = -1.0;
  EXPECT_THROW(WaypointDriver(bad, {{1, 0}}, 0.2), ParamError);
  EXPECT_THROW(WaypointDriver(WaypointDriverParams{}, {{1, 0}}, 0.0), ParamError);
}

}  // namespace
}  // namespace mjslam::explorer
