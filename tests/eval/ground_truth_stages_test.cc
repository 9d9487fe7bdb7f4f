// The indexed stages of the ground truth (spatial grid, line groups, sorted
// merges) against the direct quadratic loops they replaced, on random wall
// sets: axis-aligned walls cut into touching and overlapping pieces (as in a
// building), rotated boxes at random yaw and a rotated room cut into many
// collinear pieces. The results must be identical, bit for bit.
#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "common/pose2.h"
#include "eval/ground_truth_detail.h"

namespace mjslam::eval::detail {
namespace {

// --- The direct versions (the algorithm before indexing). ---

std::vector<Piece> DirectBoundaryPieces(const std::vector<Rectangle>& rects, double tol) {
  std::vector<Piece> pieces;
  for (std::size_t i = 0; i < rects.size(); ++i) {
    for (int e = 0; e < 4; ++e) {
      const Eigen::Vector2d a = rects[i].corners[e];
      const Eigen::Vector2d b = rects[i].corners[(e + 1) % 4];
      const double length = (b - a).norm();
      const Eigen::Vector2d d = (b - a) / length;
      const Eigen::Vector2d n(d.y(), -d.x());
      std::vector<double> cuts = {0.0, length};
      for (std::size_t j = 0; j < rects.size(); ++j) {
        double t0 = 0.0;
        double t1 = 0.0;
        if (j != i && ClipSegment(rects[j], a, d, length, tol, &t0, &t1)) {
          cuts.push_back(t0);
          cuts.push_back(t1);
        }
      }
      std::sort(cuts.begin(), cuts.end());
      for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
        if (cuts[k + 1] - cuts[k] <= 1e-12) continue;
        const Eigen::Vector2d outside = a + 0.5 * (cuts[k] + cuts[k + 1]) * d + tol * n;
        bool covered = false;
        for (std::size_t j = 0; j < rects.size() && !covered; ++j) {
          covered = j != i && rects[j].Contains(outside, 0.0);
        }
        if (!covered) pieces.push_back({a + cuts[k] * d, a + cuts[k + 1] * d, n});
      }
    }
  }
  return pieces;
}

// Merge any two overlapping pieces on one line, start over, until none.
std::vector<Piece> DirectMerge(std::vector<Piece> pieces, const GroundTruthParams& params) {
  const double tol = params.touch_tolerance_m;
  bool merged = true;
  while (merged) {
    merged = false;
    for (std::size_t i = 0; i < pieces.size() && !merged; ++i) {
      for (std::size_t j = i + 1; j < pieces.size() && !merged; ++j) {
        if (!SameLine(pieces[i], pieces[j], tol)) continue;
        const Eigen::Vector2d d(-pieces[i].n.y(), pieces[i].n.x());
        const Eigen::Vector2d origin = pieces[i].a;
        const double i1 = d.dot(pieces[i].b - origin);
        const double j0 = d.dot(pieces[j].a - origin);
        const double j1 = d.dot(pieces[j].b - origin);
        if (j0 > i1 + 2.0 * tol || j1 < -2.0 * tol) continue;
        const double lo = std::min(0.0, j0);
        const double hi = std::max(i1, j1);
        pieces[i].a = (lo == 0.0) ? pieces[i].a : pieces[j].a;
        pieces[i].b = (hi == i1) ? pieces[i].b : pieces[j].b;
        pieces.erase(pieces.begin() + static_cast<std::ptrdiff_t>(j));
        merged = true;
      }
    }
  }
  std::vector<Piece> kept;
  for (const Piece& p : pieces) {
    if ((p.b - p.a).norm() >= params.min_segment_length_m) kept.push_back(p);
  }
  return kept;
}

std::vector<int> DirectNext(const std::vector<Piece>& segments, double join) {
  std::vector<int> next(segments.size(), -1);
  for (std::size_t i = 0; i < segments.size(); ++i) {
    double best = join;
    for (std::size_t j = 0; j < segments.size(); ++j) {
      const double distance = (segments[j].a - segments[i].b).norm();
      if (j != i && distance <= best) {
        next[i] = static_cast<int>(j);
        best = distance;
      }
    }
  }
  return next;
}

// --- Random wall sets. ---

WallRectangle Aligned(double x0, double y0, double x1, double y1) {
  return {{Eigen::Vector2d(x0, y0), Eigen::Vector2d(x1, y0), Eigen::Vector2d(x1, y1),
           Eigen::Vector2d(x0, y1)}};
}

WallRectangle Rotated(const Pose2& X_WO, double hx, double hy) {
  return {{X_WO * Eigen::Vector2d(-hx, -hy), X_WO * Eigen::Vector2d(hx, -hy),
           X_WO * Eigen::Vector2d(hx, hy), X_WO * Eigen::Vector2d(-hx, hy)}};
}

// Walls on a 0.05 m lattice, 0.15 m thick, each cut into 1-4 touching or
// overlapping pieces, some with door gaps, crossing and touching each other.
std::vector<WallRectangle> BuildingLike(std::mt19937_64* rng) {
  std::uniform_int_distribution<int> cell(0, 200);
  std::uniform_int_distribution<int> span(10, 120);
  std::uniform_int_distribution<int> pieces(1, 4);
  std::uniform_int_distribution<int> joint(-1, 2);  // overlap, touch, gap (cells)
  std::vector<WallRectangle> walls;
  for (int w = 0; w < 40; ++w) {
    const double x = 0.05 * cell(*rng);
    const double y = 0.05 * cell(*rng);
    const double length = 0.05 * span(*rng);
    const int n = pieces(*rng);
    double s = 0.0;
    for (int k = 0; k < n && s < length; ++k) {
      const double end = k + 1 == n ? length : std::min(length, s + length / n);
      if (w % 2 == 0) {
        walls.push_back(Aligned(x + s, y, x + end, y + 0.15));
      } else {
        walls.push_back(Aligned(x, y + s, x + 0.15, y + end));
      }
      s = end + 0.05 * joint(*rng);
    }
  }
  return walls;
}

std::vector<WallRectangle> RotatedBoxes(std::mt19937_64* rng) {
  std::uniform_real_distribution<double> position(0.0, 8.0);
  std::uniform_real_distribution<double> yaw(-M_PI, M_PI);
  std::uniform_real_distribution<double> half(0.05, 1.0);
  std::vector<WallRectangle> walls;
  for (int k = 0; k < 60; ++k) {
    walls.push_back(Rotated(Pose2(position(*rng), position(*rng), yaw(*rng)), half(*rng),
                            half(*rng)));
  }
  return walls;
}

// A 6 x 4 m room at a random yaw, each wall cut into 40 touching pieces.
std::vector<WallRectangle> RotatedCutRoom(std::mt19937_64* rng) {
  const Pose2 X_WB(1.0, 2.0, std::uniform_real_distribution<double>(-M_PI, M_PI)(*rng));
  std::vector<WallRectangle> walls;
  const double t = 0.15;
  for (int k = 0; k < 40; ++k) {
    const double x0 = -3.0 - t + (6.0 + 2 * t) * k / 40.0;
    const double x1 = -3.0 - t + (6.0 + 2 * t) * (k + 1) / 40.0;
    const double y0 = -2.0 + 4.0 * k / 40.0;
    const double y1 = -2.0 + 4.0 * (k + 1) / 40.0;
    for (const Pose2& X_BO : {Pose2(0.5 * (x0 + x1), -2.0 - t / 2, 0.0),
                              Pose2(0.5 * (x0 + x1), 2.0 + t / 2, 0.0)}) {
      walls.push_back(Rotated(X_WB * X_BO, 0.5 * (x1 - x0), t / 2));
    }
    for (const Pose2& X_BO : {Pose2(-3.0 - t / 2, 0.5 * (y0 + y1), 0.0),
                              Pose2(3.0 + t / 2, 0.5 * (y0 + y1), 0.0)}) {
      walls.push_back(Rotated(X_WB * X_BO, t / 2, 0.5 * (y1 - y0)));
    }
  }
  return walls;
}

bool Same(const std::vector<Piece>& x, const std::vector<Piece>& y) {
  if (x.size() != y.size()) return false;
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (x[k].a != y[k].a || x[k].b != y[k].b || x[k].n != y[k].n) return false;
  }
  return true;
}

void ExpectStagesAgree(const std::vector<WallRectangle>& walls) {
  const GroundTruthParams params;
  std::vector<Rectangle> rects;
  for (std::size_t i = 0; i < walls.size(); ++i) {
    rects.push_back(MakeRectangle(walls[i], static_cast<int>(i), params.min_segment_length_m));
  }
  const std::vector<Piece> pieces = BoundaryPieces(rects, params);
  ASSERT_TRUE(Same(pieces, DirectBoundaryPieces(rects, params.touch_tolerance_m)));
  const std::vector<Piece> segments = MergeCollinear(pieces, params);
  ASSERT_TRUE(Same(segments, DirectMerge(pieces, params)));
  EXPECT_LT(segments.size(), pieces.size() + 1);
  const double join = 20.0 * params.touch_tolerance_m;
  EXPECT_EQ(NextSegments(segments, join), DirectNext(segments, join));
  // The occupied cells of a 0.05 m grid over the walls.
  const GridLimits limits(Eigen::Vector2d(-5.0, -5.0), 0.05, 400, 400);
  const Grid2<std::uint8_t> occupied = OccupiedCells(rects, limits);
  int differ = 0;
  for (int iy = 0; iy < limits.height(); ++iy) {
    for (int ix = 0; ix < limits.width(); ++ix) {
      bool inside = false;
      for (const Rectangle& r : rects) inside = inside || r.Contains(limits.CellCenter(ix, iy), 0.0);
      differ += (occupied(ix, iy) != 0) != inside;
    }
  }
  EXPECT_EQ(differ, 0);
}

TEST(GroundTruthStagesTest, IndexedStagesEqualTheDirectLoopsOnRandomWalls) {
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    {
      SCOPED_TRACE("building-like");
      ExpectStagesAgree(BuildingLike(&rng));
    }
    {
      SCOPED_TRACE("rotated boxes");
      ExpectStagesAgree(RotatedBoxes(&rng));
    }
    {
      SCOPED_TRACE("rotated room cut into pieces");
      ExpectStagesAgree(RotatedCutRoom(&rng));
    }
  }
}

TEST(GroundTruthStagesTest, ARoomCutIntoPiecesHasTheFourLinesOfTheWholeRoom) {
  std::mt19937_64 rng(3);
  const Map map = BuildGroundTruthMap({RotatedCutRoom(&rng)});
  int lines = 0;
  for (const MapFeature& f : map) lines += f.type == MapFeature::Type::kLine;
  // Four inner faces and four outer faces; four concave and four convex corners.
  EXPECT_EQ(lines, 8);
  EXPECT_EQ(map.size(), 16u);
}

}  // namespace
}  // namespace mjslam::eval::detail
