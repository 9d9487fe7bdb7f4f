#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/pose2.h"

namespace mjslam {
namespace {

TEST(AnglesTest, WrapsIntoHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(WrapAngle(kPi), kPi);
  EXPECT_DOUBLE_EQ(WrapAngle(-kPi), kPi);
  EXPECT_NEAR(WrapAngle(3.0 * kPi / 2.0), -kPi / 2.0, 1e-15);
  EXPECT_NEAR(WrapAngle(-7.0 * kPi / 2.0), kPi / 2.0, 1e-14);
  EXPECT_DOUBLE_EQ(WrapAngle(0.25), 0.25);
  for (double a = -20.0; a < 20.0; a += 0.37) {
    const double w = WrapAngle(a);
    EXPECT_GT(w, -kPi);
    EXPECT_LE(w, kPi);
    EXPECT_NEAR(std::remainder(w - a, 2.0 * kPi), 0.0, 1e-12);
  }
}

TEST(Pose2Test, ComposeMapsPointsLikeNestedTransforms) {
  const Pose2 X_AB(1.0, 2.0, 0.5);
  const Pose2 X_BC(-0.3, 0.7, 2.9);
  const Eigen::Vector2d p_CP(0.4, -1.1);
  const Eigen::Vector2d nested = X_AB * (X_BC * p_CP);
  const Eigen::Vector2d composed = (X_AB * X_BC) * p_CP;
  EXPECT_NEAR((nested - composed).norm(), 0.0, 1e-12);
  EXPECT_NEAR((X_AB * X_BC).theta, WrapAngle(0.5 + 2.9), 1e-12);
}

TEST(Pose2Test, InverseUndoesPose) {
  const Pose2 X_AB(-3.0, 0.5, -2.0);
  const Pose2 identity = X_AB * X_AB.Inverse();
  EXPECT_NEAR(identity.x, 0.0, 1e-12);
  EXPECT_NEAR(identity.y, 0.0, 1e-12);
  EXPECT_NEAR(identity.theta, 0.0, 1e-12);
  const Eigen::Vector2d p(2.0, 1.0);
  EXPECT_NEAR((X_AB.Inverse() * (X_AB * p) - p).norm(), 0.0, 1e-12);
}

TEST(Pose2Test, RotatesThenTranslates) {
  const Pose2 X_AB(1.0, 0.0, kPi / 2.0);
  const Eigen::Vector2d p_AP = X_AB * Eigen::Vector2d(1.0, 0.0);
  EXPECT_NEAR(p_AP.x(), 1.0, 1e-12);
  EXPECT_NEAR(p_AP.y(), 1.0, 1e-12);
}

}  // namespace
}  // namespace mjslam
