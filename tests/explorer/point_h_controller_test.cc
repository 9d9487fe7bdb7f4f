#include <cmath>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "explorer/point_h_controller.h"

namespace mjslam::explorer {
namespace {

// Velocity of h for a command, from the paper's Eq. (6).
Eigen::Vector2d PointVelocity(const Pose2& X_WR, const Twist2& u, double a) {
  return {u.v_mps * std::cos(X_WR.theta) - a * u.w_radps * std::sin(X_WR.theta),
          u.v_mps * std::sin(X_WR.theta) + a * u.w_radps * std::cos(X_WR.theta)};
}

TEST(PointHControllerTest, CommandProducesDesiredPointVelocity) {
  const double a = 0.2;
  for (double th = -3.0; th < 3.2; th += 0.5) {
    const Pose2 X_WR(1.0, -2.0, th);
    const Eigen::Vector2d desired(0.3 * std::cos(1.1 * th), -0.25 + 0.1 * th);
    const Twist2 u = CommandForPointVelocity(X_WR, desired, a);
    EXPECT_NEAR((PointVelocity(X_WR, u, a) - desired).norm(), 0.0, 1e-12) << "th " << th;
  }
}

TEST(PointHControllerTest, SidewaysVelocityNeedsRotation) {
  const Twist2 u = CommandForPointVelocity(Pose2(0, 0, 0), {0.0, 0.1}, 0.2);
  EXPECT_NEAR(u.v_mps, 0.0, 1e-15);
  EXPECT_NEAR(u.w_radps, 0.5, 1e-15);
}

TEST(PointHControllerTest, SaturationKeepsCurvature) {
  const Twist2 u = SaturateKeepingCurvature({1.0, 3.0}, 0.5, 1.0);
  EXPECT_NEAR(u.w_radps, 1.0, 1e-15);
  EXPECT_NEAR(u.v_mps / u.w_radps, 1.0 / 3.0, 1e-15);
  const Twist2 v = SaturateKeepingCurvature({-2.0, 0.5}, 0.5, 1.0);
  EXPECT_NEAR(v.v_mps, -0.5, 1e-15);
  EXPECT_NEAR(v.w_radps, 0.125, 1e-15);
  const Twist2 inside = SaturateKeepingCurvature({0.1, -0.2}, 0.5, 1.0);
  EXPECT_EQ(inside.v_mps, 0.1);
  EXPECT_EQ(inside.w_radps, -0.2);
}

TEST(PointHControllerTest, RateLimitBoundsTheChange) {
  const Twist2 u = RateLimit({0.0, 0.0}, {1.0, -1.0}, 0.05, 0.2);
  EXPECT_DOUBLE_EQ(u.v_mps, 0.05);
  EXPECT_DOUBLE_EQ(u.w_radps, -0.2);
  const Twist2 reached = RateLimit({0.3, 0.1}, {0.32, 0.0}, 0.05, 0.2);
  EXPECT_DOUBLE_EQ(reached.v_mps, 0.32);
  EXPECT_DOUBLE_EQ(reached.w_radps, 0.0);
}

}  // namespace
}  // namespace mjslam::explorer
