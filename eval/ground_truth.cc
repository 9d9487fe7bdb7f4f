#include "eval/ground_truth.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/angles.h"
#include "common/grid2.h"
#include "common/interrupt.h"
#include "common/segments.h"

namespace mjslam::eval {

std::vector<ParamProblem> GroundTruthParams::Validate() const {
  ParamChecker check;
  check.Positive("touch_tolerance_m", touch_tolerance_m);
  check.Positive("min_segment_length_m", min_segment_length_m);
  check.InRange("corner_min_angle_deg", corner_min_angle_deg, 0.0, 90.0);
  return check.problems();
}

namespace {

// A rectangle as centre, unit axes and half extents, corners counter-clockwise.
struct Rectangle {
  Eigen::Vector2d center;
  Eigen::Vector2d u;  // unit axis along the first side
  Eigen::Vector2d v;  // unit axis along the second side (u rotated +90 deg)
  double half_u = 0.0;
  double half_v = 0.0;
  std::array<Eigen::Vector2d, 4> corners;  // counter-clockwise

  // p in the rectangle's own coordinates.
  Eigen::Vector2d Local(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d d = p - center;
    return {d.dot(u), d.dot(v)};
  }
  // Inside the closed rectangle grown by `margin` on every side.
  bool Contains(const Eigen::Vector2d& p, double margin) const {
    const Eigen::Vector2d q = Local(p);
    return std::abs(q.x()) <= half_u + margin && std::abs(q.y()) <= half_v + margin;
  }
};

Rectangle MakeRectangle(const WallRectangle& wall, int index, double min_side) {
  const std::string name = "wall " + std::to_string(index);
  for (const Eigen::Vector2d& p : wall.corners_W) {
    if (!p.allFinite()) throw std::invalid_argument(name + ": corner is not finite");
  }
  std::array<Eigen::Vector2d, 4> c = wall.corners_W;
  // Counter-clockwise order (positive signed area).
  double area2 = 0.0;
  for (int i = 0; i < 4; ++i) area2 += Cross(c[i], c[(i + 1) % 4]);
  if (area2 < 0.0) std::swap(c[1], c[3]);
  const Eigen::Vector2d side_u = c[1] - c[0];
  const Eigen::Vector2d side_v = c[3] - c[0];
  const double length_u = side_u.norm();
  const double length_v = side_v.norm();
  if (length_u < min_side || length_v < min_side) {
    throw std::invalid_argument(name + ": a side is shorter than " + ValueText(min_side) +
                                " m (got " + ValueText(std::min(length_u, length_v)) + ")");
  }
  // Right angles and a closed shape, to 1e-6 of the size.
  const double size = std::max(length_u, length_v);
  if (std::abs(side_u.dot(side_v)) > 1e-6 * length_u * length_v ||
      (c[2] - (c[1] + side_v)).norm() > 1e-6 * size) {
    throw std::invalid_argument(name + ": its corners do not form a rectangle");
  }
  Rectangle r;
  r.corners = c;
  r.center = 0.25 * (c[0] + c[1] + c[2] + c[3]);
  r.u = side_u / length_u;
  r.v = Eigen::Vector2d(-r.u.y(), r.u.x());
  r.half_u = 0.5 * length_u;
  r.half_v = 0.5 * length_v;
  return r;
}

// Parameter interval [t0, t1] of the segment a + t d (t in [0, length]) inside
// the rectangle grown by `margin` (slab clipping). False if none.
bool ClipSegment(const Rectangle& r, const Eigen::Vector2d& a, const Eigen::Vector2d& d,
                 double length, double margin, double* t0, double* t1) {
  double lo = 0.0;
  double hi = length;
  const Eigen::Vector2d a_local = r.Local(a);
  const Eigen::Vector2d d_local(d.dot(r.u), d.dot(r.v));
  const double half[2] = {r.half_u + margin, r.half_v + margin};
  for (int k = 0; k < 2; ++k) {
    if (std::abs(d_local[k]) < 1e-15) {
      if (std::abs(a_local[k]) > half[k]) return false;
      continue;
    }
    double ta = (-half[k] - a_local[k]) / d_local[k];
    double tb = (half[k] - a_local[k]) / d_local[k];
    if (ta > tb) std::swap(ta, tb);
    lo = std::max(lo, ta);
    hi = std::min(hi, tb);
    if (lo > hi) return false;
  }
  *t0 = lo;
  *t1 = hi;
  return true;
}

// A straight piece of the union's boundary, traversed with the obstacle on
// its left: from a to b, outward (free-side) normal n.
struct Piece {
  Eigen::Vector2d a;
  Eigen::Vector2d b;
  Eigen::Vector2d n;
};

// True when two pieces lie on one line facing the same way.
bool SameLine(const Piece& p, const Piece& q, double tolerance) {
  if (p.n.dot(q.n) < 1.0 - 1e-9) return false;
  return std::abs(p.n.dot(q.a - p.a)) <= tolerance && std::abs(p.n.dot(q.b - p.a)) <= tolerance;
}

// The boundary pieces of the union, merged into maximal segments.
std::vector<Piece> BoundarySegments(const std::vector<Rectangle>& rects,
                                    const GroundTruthParams& params) {
  const double tol = params.touch_tolerance_m;
  std::vector<Piece> pieces;
  for (std::size_t i = 0; i < rects.size(); ++i) {
    ThrowIfInterrupted("ground truth");
    for (int e = 0; e < 4; ++e) {
      const Eigen::Vector2d a = rects[i].corners[e];
      const Eigen::Vector2d b = rects[i].corners[(e + 1) % 4];
      const double length = (b - a).norm();
      const Eigen::Vector2d d = (b - a) / length;
      const Eigen::Vector2d n(d.y(), -d.x());  // right of d: outward for CCW
      // Split where the edge enters or leaves another (grown) rectangle.
      std::vector<double> cuts = {0.0, length};
      for (std::size_t j = 0; j < rects.size(); ++j) {
        if (j == i) continue;
        double t0 = 0.0;
        double t1 = 0.0;
        if (ClipSegment(rects[j], a, d, length, tol, &t0, &t1)) {
          cuts.push_back(t0);
          cuts.push_back(t1);
        }
      }
      std::sort(cuts.begin(), cuts.end());
      for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
        if (cuts[k + 1] - cuts[k] <= 1e-12) continue;
        // Kept when just outside its midpoint there is no other wall.
        const Eigen::Vector2d mid = a + 0.5 * (cuts[k] + cuts[k + 1]) * d;
        const Eigen::Vector2d outside = mid + tol * n;
        bool covered = false;
        for (std::size_t j = 0; j < rects.size() && !covered; ++j) {
          covered = j != i && rects[j].Contains(outside, 0.0);
        }
        if (!covered) pieces.push_back({a + cuts[k] * d, a + cuts[k + 1] * d, n});
      }
    }
  }

  // Merge pieces on one line that overlap or touch, until none do.
  bool merged = true;
  while (merged) {
    ThrowIfInterrupted("ground truth");
    merged = false;
    for (std::size_t i = 0; i < pieces.size() && !merged; ++i) {
      for (std::size_t j = i + 1; j < pieces.size() && !merged; ++j) {
        if (!SameLine(pieces[i], pieces[j], tol)) continue;
        const Eigen::Vector2d d(-pieces[i].n.y(), pieces[i].n.x());  // direction a -> b
        const Eigen::Vector2d origin = pieces[i].a;
        const double i0 = 0.0;
        const double i1 = d.dot(pieces[i].b - origin);
        const double j0 = d.dot(pieces[j].a - origin);
        const double j1 = d.dot(pieces[j].b - origin);
        if (j0 > i1 + 2.0 * tol || j1 < i0 - 2.0 * tol) continue;
        const double lo = std::min(i0, j0);
        const double hi = std::max(i1, j1);
        pieces[i].a = (lo == i0) ? pieces[i].a : pieces[j].a;
        pieces[i].b = (hi == i1) ? pieces[i].b : pieces[j].b;
        pieces.erase(pieces.begin() + static_cast<std::ptrdiff_t>(j));
        merged = true;
      }
    }
  }
  std::vector<Piece> segments;
  for (const Piece& p : pieces) {
    if ((p.b - p.a).norm() >= params.min_segment_length_m) segments.push_back(p);
  }
  return segments;
}

}  // namespace

Map BuildGroundTruthMap(const std::vector<WallRectangle>& walls, const GroundTruthParams& params) {
  params.ValidateOrThrow();
  std::vector<Rectangle> rects;
  for (std::size_t i = 0; i < walls.size(); ++i) {
    rects.push_back(MakeRectangle(walls[i], static_cast<int>(i), params.min_segment_length_m));
  }
  std::vector<Piece> segments = BoundarySegments(rects, params);

  // Corners: where a segment's end meets another's start at a real angle.
  // The split of a touching junction can leave the two a few tolerances
  // apart (more at shallow crossings), hence the joining distance.
  const double join = 20.0 * params.touch_tolerance_m;
  const double min_sin = std::sin(DegToRad(params.corner_min_angle_deg));
  struct Corner {
    Eigen::Vector2d p;
    bool convex;
    int incoming;
    int outgoing;
  };
  std::vector<Corner> corners;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    int best = -1;
    double best_distance = join;
    for (std::size_t j = 0; j < segments.size(); ++j) {
      if (j == i) continue;
      const double distance = (segments[j].a - segments[i].b).norm();
      if (distance <= best_distance) {
        best = static_cast<int>(j);
        best_distance = distance;
      }
    }
    if (best < 0) continue;
    const Eigen::Vector2d d_in = (segments[i].b - segments[i].a).normalized();
    const Eigen::Vector2d d_out = (segments[best].b - segments[best].a).normalized();
    const double turn = Cross(d_in, d_out);
    if (std::abs(turn) < min_sin) continue;
    // Obstacle on the left: a left turn wraps around the obstacle (convex).
    corners.push_back({LineIntersection(segments[i].a, segments[i].b, segments[best].a,
                                        segments[best].b),
                       turn > 0.0, static_cast<int>(i),
                       best});
  }
  // The segments end exactly at their corners.
  for (const Corner& c : corners) {
    segments[c.incoming].b = c.p;
    segments[c.outgoing].a = c.p;
  }

  Map map;
  for (const Piece& s : segments) {
    MapFeature line;
    line.id = static_cast<int>(map.size());
    line.type = MapFeature::Type::kLine;
    Eigen::Vector2d n = s.n;
    double r = n.dot(s.a);
    if (r < 0.0) {
      r = -r;
      n = -n;
    }
    line.params = {r, WrapAngle(std::atan2(n.y(), n.x())) + 0.0};  // no -0
    line.has_segment = true;
    line.p_WA = s.a;
    line.p_WB = s.b;
    map.push_back(line);
  }
  for (const Corner& c : corners) {
    MapFeature corner;
    corner.id = static_cast<int>(map.size());
    corner.type = MapFeature::Type::kCorner;
    corner.params = c.p;
    corner.corner_kind = c.convex ? MapFeature::CornerKind::kConvex
                                  : MapFeature::CornerKind::kConcave;
    corner.free_direction_W = (segments[c.incoming].n + segments[c.outgoing].n).normalized();
    map.push_back(corner);
  }
  return map;
}

Map ReachableFeatures(const Map& truth, const std::vector<WallRectangle>& walls,
                      const Eigen::Vector2d& p_W_start, double cell_m) {
  if (!(cell_m > 0.0)) {
    throw std::invalid_argument("reachable features: cell size must be > 0 (got " +
                                ValueText(cell_m) + ")");
  }
  std::vector<Rectangle> rects;
  for (std::size_t i = 0; i < walls.size(); ++i) {
    rects.push_back(MakeRectangle(walls[i], static_cast<int>(i), 1e-9));
  }
  // The grid covers the walls, the start and the features, plus a margin
  // of two cells, so that the outside of a building is connected around it.
  Eigen::Vector2d lo = p_W_start;
  Eigen::Vector2d hi = p_W_start;
  for (const Rectangle& r : rects) {
    for (const Eigen::Vector2d& c : r.corners) {
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
  }
  lo.array() -= 2.0 * cell_m;
  hi.array() += 2.0 * cell_m;
  const GridLimits limits(lo, cell_m, static_cast<int>(std::ceil((hi.x() - lo.x()) / cell_m)),
                          static_cast<int>(std::ceil((hi.y() - lo.y()) / cell_m)));
  // A cell is free when its centre is in no wall.
  auto free_cell = [&](int ix, int iy) {
    const Eigen::Vector2d centre = limits.CellCenter(ix, iy);
    for (const Rectangle& r : rects) {
      if (r.Contains(centre, 0.0)) return false;
    }
    return true;
  };
  const Eigen::Vector2i start = limits.CellOf(p_W_start);
  if (!free_cell(start.x(), start.y())) {
    throw std::invalid_argument("reachable features: the start point (" +
                                ValueText(p_W_start.x()) + ", " + ValueText(p_W_start.y()) +
                                ") is inside a wall");
  }
  // Flood fill, 4-connected.
  Grid2<std::uint8_t> reached(limits, 0);
  FloodFill(start, Connectivity::kFour, free_cell, &reached);
  auto reachable = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2i cell = limits.CellOf(p);
    return limits.Contains(cell) && reached(cell.x(), cell.y()) != 0;
  };
  Map kept;
  for (const MapFeature& f : truth) {
    Eigen::Vector2d probe;
    if (f.type == MapFeature::Type::kLine) {
      const Eigen::Vector2d d = (f.p_WB - f.p_WA).normalized();
      probe = 0.5 * (f.p_WA + f.p_WB) + 1.5 * cell_m * Eigen::Vector2d(d.y(), -d.x());
    } else {
      probe = f.params + 1.5 * cell_m * f.free_direction_W;
    }
    if (!reachable(probe)) continue;
    kept.push_back(f);
    kept.back().id = static_cast<int>(kept.size()) - 1;
  }
  return kept;
}

}  // namespace mjslam::eval
