#include "common/segments.h"

#include <cmath>

#include <gtest/gtest.h>

namespace mjslam {
namespace {

TEST(SegmentsTest, CrossIsPositiveForALeftTurn) {
  EXPECT_EQ(Cross({1.0, 0.0}, {0.0, 2.0}), 2.0);
  EXPECT_EQ(Cross({0.0, 2.0}, {1.0, 0.0}), -2.0);
  EXPECT_EQ(Cross({1.0, 1.0}, {2.0, 2.0}), 0.0);
}

TEST(SegmentsTest, PointSegmentDistanceToTheInsideAndToTheEnds) {
  const Eigen::Vector2d a(1.0, 1.0);
  const Eigen::Vector2d b(5.0, 1.0);
  EXPECT_DOUBLE_EQ(PointSegmentDistance({3.0, 4.0}, a, b), 3.0);
  EXPECT_DOUBLE_EQ(PointSegmentDistance({3.0, -1.0}, a, b), 2.0);
  EXPECT_DOUBLE_EQ(PointSegmentDistance({8.0, 5.0}, a, b), 5.0);   // beyond b
  EXPECT_DOUBLE_EQ(PointSegmentDistance({-2.0, -3.0}, a, b), 5.0);  // before a
  EXPECT_DOUBLE_EQ(PointSegmentDistance({2.0, 1.0}, a, b), 0.0);
}

TEST(SegmentsTest, RaySegmentCastHitsInFrontOnlyWithinTheSegment) {
  const Eigen::Vector2d a(3.0, -1.0);
  const Eigen::Vector2d b(3.0, 2.0);
  EXPECT_DOUBLE_EQ(RaySegmentCast({0.0, 0.0}, {1.0, 0.0}, a, b), 3.0);
  EXPECT_DOUBLE_EQ(RaySegmentCast({1.0, 2.0}, {1.0, 0.0}, a, b), 2.0);  // end point
  const double diagonal = std::sqrt(0.5);
  EXPECT_NEAR(RaySegmentCast({1.0, -1.0}, {diagonal, diagonal}, a, b), 2.0 * std::sqrt(2.0),
              1e-12);
  EXPECT_TRUE(std::isinf(RaySegmentCast({0.0, 0.0}, {diagonal, diagonal}, a, b)));  // above b
  EXPECT_TRUE(std::isinf(RaySegmentCast({0.0, 0.0}, {-1.0, 0.0}, a, b)));  // behind
  EXPECT_TRUE(std::isinf(RaySegmentCast({0.0, 2.5}, {1.0, 0.0}, a, b)));   // past b
  EXPECT_TRUE(std::isinf(RaySegmentCast({0.0, 0.0}, {0.0, 1.0}, a, b)));   // parallel
  // Nearly parallel (|u x e| = 2e-14): not met with the default threshold,
  // met with a smaller one.
  const Eigen::Vector2d c(2.0, -1e-14);
  const Eigen::Vector2d d(4.0, 1e-14);
  EXPECT_TRUE(std::isinf(RaySegmentCast({0.0, 0.0}, {1.0, 0.0}, c, d)));
  EXPECT_NEAR(RaySegmentCast({0.0, 0.0}, {1.0, 0.0}, c, d, 1e-15), 3.0, 1e-9);
}

TEST(SegmentsTest, LineIntersectionOfTwoLines) {
  const Eigen::Vector2d p =
      LineIntersection({0.0, 0.0}, {1.0, 1.0}, {4.0, 0.0}, {4.0, 1.0});
  EXPECT_DOUBLE_EQ(p.x(), 4.0);
  EXPECT_DOUBLE_EQ(p.y(), 4.0);
  const Eigen::Vector2d q =
      LineIntersection({0.0, 2.0}, {3.0, 2.0}, {1.0, -1.0}, {2.0, 1.0});
  EXPECT_DOUBLE_EQ(q.x(), 2.5);
  EXPECT_DOUBLE_EQ(q.y(), 2.0);
}

}  // namespace
}  // namespace mjslam
