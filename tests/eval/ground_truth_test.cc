// Ground truth from wall footprints: overlapping, touching (T and L) and
// rotated walls on synthetic wall sets with known boundaries.
#include "eval/ground_truth.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/pose2.h"

namespace mjslam::eval {
namespace {

// An axis-aligned wall [x0, x1] x [y0, y1], corners clockwise on purpose.
WallRectangle Box(double x0, double y0, double x1, double y1) {
  return {{Eigen::Vector2d(x0, y0), Eigen::Vector2d(x0, y1), Eigen::Vector2d(x1, y1),
           Eigen::Vector2d(x1, y0)}};
}

// A wall of half extents (hx, hy) at pose X_WO.
WallRectangle Rotated(const Pose2& X_WO, double hx, double hy) {
  return {{X_WO * Eigen::Vector2d(-hx, -hy), X_WO * Eigen::Vector2d(hx, -hy),
           X_WO * Eigen::Vector2d(hx, hy), X_WO * Eigen::Vector2d(-hx, hy)}};
}

int Count(const Map& map, MapFeature::Type type) {
  return static_cast<int>(std::count_if(map.begin(), map.end(),
                                        [type](const MapFeature& f) { return f.type == type; }));
}

int CountCorners(const Map& map, MapFeature::CornerKind kind) {
  return static_cast<int>(std::count_if(map.begin(), map.end(), [kind](const MapFeature& f) {
    return f.type == MapFeature::Type::kCorner && f.corner_kind == kind;
  }));
}

// The corner nearest to p, or null.
const MapFeature* CornerNear(const Map& map, const Eigen::Vector2d& p, double within = 1e-6) {
  for (const MapFeature& f : map) {
    if (f.type == MapFeature::Type::kCorner && (f.params - p).norm() <= within) return &f;
  }
  return nullptr;
}

// The line whose segment has these endpoints (either order).
const MapFeature* LineWithSegment(const Map& map, const Eigen::Vector2d& a,
                                  const Eigen::Vector2d& b, double within = 1e-6) {
  for (const MapFeature& f : map) {
    if (f.type != MapFeature::Type::kLine) continue;
    if (((f.p_WA - a).norm() <= within && (f.p_WB - b).norm() <= within) ||
        ((f.p_WA - b).norm() <= within && (f.p_WB - a).norm() <= within)) {
      return &f;
    }
  }
  return nullptr;
}

// Every line's segment lies on its (r, al) line and r is canonical.
void ExpectLinesConsistent(const Map& map) {
  for (const MapFeature& f : map) {
    if (f.type != MapFeature::Type::kLine) continue;
    EXPECT_GE(f.params.x(), 0.0);
    EXPECT_GT(f.params.y(), -kPi);
    EXPECT_LE(f.params.y(), kPi);
    const Eigen::Vector2d n(std::cos(f.params.y()), std::sin(f.params.y()));
    EXPECT_NEAR(n.dot(f.p_WA), f.params.x(), 1e-9);
    EXPECT_NEAR(n.dot(f.p_WB), f.params.x(), 1e-9);
  }
}

TEST(GroundTruthTest, SingleWallIsFourLinesAndFourConvexCorners) {
  const Map map = BuildGroundTruthMap({Box(1.0, 2.0, 5.0, 2.2)});
  EXPECT_EQ(Count(map, MapFeature::Type::kLine), 4);
  EXPECT_EQ(CountCorners(map, MapFeature::CornerKind::kConvex), 4);
  EXPECT_EQ(CountCorners(map, MapFeature::CornerKind::kConcave), 0);
  // The bottom face is the line y = 2: canonically al = pi/2, r = 2 (the
  // polar form does not depend on which side the free space is).
  const MapFeature* bottom = LineWithSegment(map, {1.0, 2.0}, {5.0, 2.0});
  ASSERT_NE(bottom, nullptr);
  EXPECT_NEAR(bottom->params.x(), 2.0, 1e-12);
  EXPECT_NEAR(bottom->params.y(), kPi / 2, 1e-12);
  ExpectLinesConsistent(map);
}

TEST(GroundTruthTest, RoomOfFourOverlappingWallsHasInnerAndOuterBoundary) {
  // The shape of worlds/room.xml: walls 0.15 m thick, the long ones overlap
  // the short ones at the four corners.
  const std::vector<WallRectangle> walls = {
      Box(-4.15, -3.15, 4.15, -3.0), Box(4.0, -3.15, 4.15, 3.15),
      Box(-4.15, 3.0, 4.15, 3.15), Box(-4.15, -3.15, -4.0, 3.15)};
  const Map map = BuildGroundTruthMap(walls);
  // Inside: 4 lines and 4 concave corners; outside: 4 lines and 4 convex.
  EXPECT_EQ(Count(map, MapFeature::Type::kLine), 8);
  EXPECT_EQ(CountCorners(map, MapFeature::CornerKind::kConcave), 4);
  EXPECT_EQ(CountCorners(map, MapFeature::CornerKind::kConvex), 4);
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(4.0, 3.0), Eigen::Vector2d(-4.0, 3.0),
                                   Eigen::Vector2d(-4.0, -3.0), Eigen::Vector2d(4.0, -3.0)}) {
    const MapFeature* c = CornerNear(map, p);
    ASSERT_NE(c, nullptr) << p.transpose();
    EXPECT_EQ(c->corner_kind, MapFeature::CornerKind::kConcave);
  }
  // The inner south face, whole, between the two concave corners.
  const MapFeature* south = LineWithSegment(map, {-4.0, -3.0}, {4.0, -3.0});
  ASSERT_NE(south, nullptr);
  EXPECT_NEAR(south->params.x(), 3.0, 1e-12);
  EXPECT_NEAR(south->params.y(), -kPi / 2, 1e-12);
  ASSERT_NE(CornerNear(map, {4.15, 3.15}), nullptr);
  ExpectLinesConsistent(map);
}

TEST(GroundTruthTest, TouchingTJunctionMakesTwoConcaveCorners) {
  // A stem standing on a long wall, touching it exactly.
  const Map map = BuildGroundTruthMap({Box(0.0, -0.2, 6.0, 0.0), Box(2.9, 0.0, 3.1, 2.0)});
  EXPECT_EQ(CountCorners(map, MapFeature::CornerKind::kConcave), 2);
  EXPECT_EQ(CountCorners(map, MapFeature::CornerKind::kConvex), 6);
  // The long wall's top face is split in two at the stem; the bottom is whole.
  EXPECT_EQ(Count(map, MapFeature::Type::kLine), 8);
  EXPECT_NE(LineWithSegment(map, {0.0, 0.0}, {2.9, 0.0}), nullptr);
  EXPECT_NE(LineWithSegment(map, {3.1, 0.0}, {6.0, 0.0}), nullptr);
  EXPECT_NE(LineWithSegment(map, {0.0, -0.2}, {6.0, -0.2}), nullptr);
  EXPECT_NE(LineWithSegment(map, {2.9, 0.0}, {2.9, 2.0}), nullptr);
  const MapFeature* c = CornerNear(map, {2.9, 0.0});
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->corner_kind, MapFeature::CornerKind::kConcave);
  ExpectLinesConsistent(map);
}

TEST(GroundTruthTest, TouchingWithinToleranceStillJoinsButAGapDoesNot) {
  // 50 um apart: touching (tolerance 0.1 mm), same as above.
  const Map touching = BuildGroundTruthMap({Box(0.0, -0.2, 6.0, 0.0), Box(2.9, 5e-5, 3.1, 2.0)});
  EXPECT_EQ(CountCorners(touching, MapFeature::CornerKind::kConcave), 2);
  // 1 cm apart: two separate walls, 8 lines and 8 convex corners.
  const Map apart = BuildGroundTruthMap({Box(0.0, -0.2, 6.0, 0.0), Box(2.9, 0.01, 3.1, 2.0)});
  EXPECT_EQ(CountCorners(apart, MapFeature::CornerKind::kConcave), 0);
  EXPECT_EQ(CountCorners(apart, MapFeature::CornerKind::kConvex), 8);
  EXPECT_EQ(Count(apart, MapFeature::Type::kLine), 8);
}

TEST(GroundTruthTest, LJunctionTouchingAndOverlappingGiveTheSameBoundary) {
  // Touching end to side, and overlapping in a square: the same L shape.
  const Map touching = BuildGroundTruthMap({Box(0.0, 0.0, 4.0, 0.15), Box(0.0, 0.15, 0.15, 3.0)});
  const Map overlapping = BuildGroundTruthMap({Box(0.0, 0.0, 4.0, 0.15), Box(0.0, 0.0, 0.15, 3.0)});
  for (const Map* map : {&touching, &overlapping}) {
    EXPECT_EQ(Count(*map, MapFeature::Type::kLine), 6);
    EXPECT_EQ(CountCorners(*map, MapFeature::CornerKind::kConvex), 5);
    EXPECT_EQ(CountCorners(*map, MapFeature::CornerKind::kConcave), 1);
    const MapFeature* inner = CornerNear(*map, {0.15, 0.15});
    ASSERT_NE(inner, nullptr);
    EXPECT_EQ(inner->corner_kind, MapFeature::CornerKind::kConcave);
    // The outer faces are whole: x = 0 from y 3 to 0, y = 0 from x 0 to 4.
    EXPECT_NE(LineWithSegment(*map, {0.0, 3.0}, {0.0, 0.0}), nullptr);
    EXPECT_NE(LineWithSegment(*map, {0.0, 0.0}, {4.0, 0.0}), nullptr);
    ExpectLinesConsistent(*map);
  }
}

TEST(GroundTruthTest, CollinearWallsSideBySideMergeIntoOneFace) {
  // Two walls end to end (touching) and two overlapping along their length:
  // each pair is one rectangle, 4 lines and 4 convex corners.
  for (const std::vector<WallRectangle>& walls :
       {std::vector<WallRectangle>{Box(0.0, 0.0, 2.0, 0.2), Box(2.0, 0.0, 5.0, 0.2)},
        std::vector<WallRectangle>{Box(0.0, 0.0, 3.0, 0.2), Box(1.0, 0.0, 5.0, 0.2)}}) {
    const Map map = BuildGroundTruthMap(walls);
    EXPECT_EQ(Count(map, MapFeature::Type::kLine), 4);
    EXPECT_EQ(CountCorners(map, MapFeature::CornerKind::kConvex), 4);
    EXPECT_EQ(CountCorners(map, MapFeature::CornerKind::kConcave), 0);
    EXPECT_NE(LineWithSegment(map, {0.0, 0.0}, {5.0, 0.0}), nullptr);
    EXPECT_NE(LineWithSegment(map, {0.0, 0.2}, {5.0, 0.2}), nullptr);
  }
}

TEST(GroundTruthTest, CrossingRotatedWallsMakeAStar) {
  // Two walls crossing at their centres at 60 degrees: four ends (8 convex
  // corners) and 4 concave corners where the faces cross; each long face is
  // cut in two by the other wall.
  const Pose2 X_WA(1.0, -2.0, DegToRad(20.0));
  const Pose2 X_WB(1.0, -2.0, DegToRad(80.0));
  const Map map = BuildGroundTruthMap({Rotated(X_WA, 2.0, 0.1), Rotated(X_WB, 2.0, 0.1)});
  EXPECT_EQ(CountCorners(map, MapFeature::CornerKind::kConvex), 8);
  EXPECT_EQ(CountCorners(map, MapFeature::CornerKind::kConcave), 4);
  EXPECT_EQ(Count(map, MapFeature::Type::kLine), 12);
  // A tip corner of wall A, exactly.
  const MapFeature* tip = CornerNear(map, X_WA * Eigen::Vector2d(2.0, 0.1), 1e-9);
  ASSERT_NE(tip, nullptr);
  EXPECT_EQ(tip->corner_kind, MapFeature::CornerKind::kConvex);
  // Every line's al is the direction of one of the walls' face normals.
  for (const MapFeature& f : map) {
    if (f.type != MapFeature::Type::kLine) continue;
    const double a = std::fmod(RadToDeg(f.params.y()) + 360.0, 90.0);
    EXPECT_NEAR(std::min(std::abs(a - 20.0), std::abs(a - 80.0)), 0.0, 1e-9);
  }
  ExpectLinesConsistent(map);
}

TEST(GroundTruthTest, RotatedRoomMatchesAxisAlignedRoomRotated) {
  // The room test's walls rotated by 30 degrees about (1, 2): the same
  // features, rotated.
  const Pose2 X_WQ(1.0, 2.0, DegToRad(30.0));
  auto rotate = [&X_WQ](const WallRectangle& w) {
    WallRectangle out;
    for (int i = 0; i < 4; ++i) out.corners_W[i] = X_WQ * w.corners_W[i];
    return out;
  };
  const std::vector<WallRectangle> walls = {
      Box(-4.15, -3.15, 4.15, -3.0), Box(4.0, -3.15, 4.15, 3.15),
      Box(-4.15, 3.0, 4.15, 3.15), Box(-4.15, -3.15, -4.0, 3.15)};
  std::vector<WallRectangle> rotated;
  for (const WallRectangle& w : walls) rotated.push_back(rotate(w));
  const Map a = BuildGroundTruthMap(walls);
  const Map b = BuildGroundTruthMap(rotated);
  ASSERT_EQ(Count(b, MapFeature::Type::kLine), 8);
  for (const MapFeature& f : a) {
    if (f.type != MapFeature::Type::kCorner) continue;
    const MapFeature* g = CornerNear(b, X_WQ * f.params, 1e-6);
    ASSERT_NE(g, nullptr) << f.params.transpose();
    EXPECT_EQ(g->corner_kind, f.corner_kind);
  }
  for (const MapFeature& f : a) {
    if (f.type != MapFeature::Type::kLine) continue;
    EXPECT_NE(LineWithSegment(b, X_WQ * f.p_WA, X_WQ * f.p_WB, 1e-6), nullptr);
  }
  ExpectLinesConsistent(b);
}

TEST(GroundTruthTest, ReachableFeaturesAreTheInsideOfTheRoom) {
  const std::vector<WallRectangle> walls = {
      Box(-4.15, -3.15, 4.15, -3.0), Box(4.0, -3.15, 4.15, 3.15),
      Box(-4.15, 3.0, 4.15, 3.15), Box(-4.15, -3.15, -4.0, 3.15),
      Box(0.0, -1.0, 1.0, -0.8)};  // a box standing in the room
  const Map all = BuildGroundTruthMap(walls);
  ASSERT_EQ(Count(all, MapFeature::Type::kLine), 12);
  // From inside: the room's 4 inner faces and concave corners, the box's 4
  // faces and convex corners; not the 4 outer faces and corners.
  const Map inside = ReachableFeatures(all, walls, {-2.8, -1.8});
  EXPECT_EQ(Count(inside, MapFeature::Type::kLine), 8);
  EXPECT_EQ(CountCorners(inside, MapFeature::CornerKind::kConcave), 4);
  EXPECT_EQ(CountCorners(inside, MapFeature::CornerKind::kConvex), 4);
  EXPECT_EQ(CornerNear(inside, {4.15, 3.15}), nullptr);
  EXPECT_NE(CornerNear(inside, {1.0, -0.8}), nullptr);
  for (std::size_t i = 0; i < inside.size(); ++i) EXPECT_EQ(inside[i].id, static_cast<int>(i));
  // From outside: the outer faces and corners only.
  const Map outside = ReachableFeatures(all, walls, {10.0, 0.0});
  EXPECT_EQ(Count(outside, MapFeature::Type::kLine), 4);
  EXPECT_EQ(CountCorners(outside, MapFeature::CornerKind::kConvex), 4);
  EXPECT_EQ(CountCorners(outside, MapFeature::CornerKind::kConcave), 0);
  EXPECT_THROW(ReachableFeatures(all, walls, {0.5, -0.9}), std::invalid_argument);
}

TEST(GroundTruthTest, WallInsideAnotherAddsNothing) {
  const Map map = BuildGroundTruthMap({Box(0.0, 0.0, 4.0, 1.0), Box(1.0, 0.2, 2.0, 0.8)});
  EXPECT_EQ(Count(map, MapFeature::Type::kLine), 4);
  EXPECT_EQ(CountCorners(map, MapFeature::CornerKind::kConvex), 4);
}

TEST(GroundTruthTest, RejectsWallsThatAreNotRectangles) {
  WallRectangle skew = Box(0.0, 0.0, 1.0, 1.0);
  skew.corners_W[2] = {1.5, 1.0};
  try {
    BuildGroundTruthMap({Box(5.0, 5.0, 6.0, 6.0), skew});
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("wall 1"), std::string::npos) << error.what();
  }
  WallRectangle flat = Box(0.0, 0.0, 1.0, 0.0);
  EXPECT_THROW(BuildGroundTruthMap({flat}), std::invalid_argument);
  EXPECT_TRUE(BuildGroundTruthMap({}).empty());
}

}  // namespace
}  // namespace mjslam::eval
