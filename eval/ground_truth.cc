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
#include "eval/ground_truth_detail.h"

namespace mjslam::eval {

std::vector<ParamProblem> GroundTruthParams::Validate() const {
  ParamChecker check;
  check.Positive("touch_tolerance_m", touch_tolerance_m);
  check.Positive("min_segment_length_m", min_segment_length_m);
  check.InRange("corner_min_angle_deg", corner_min_angle_deg, 0.0, 90.0);
  return check.problems();
}

namespace detail {

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

Box2 BoundsOf(const Rectangle& r, double margin) {
  Box2 box{r.corners[0], r.corners[0]};
  for (const Eigen::Vector2d& c : r.corners) {
    box.lo = box.lo.cwiseMin(c);
    box.hi = box.hi.cwiseMax(c);
  }
  box.lo.array() -= margin;
  box.hi.array() += margin;
  return box;
}

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

bool SameLine(const Piece& p, const Piece& q, double tolerance) {
  if (p.n.dot(q.n) < 1.0 - 1e-9) return false;
  return std::abs(p.n.dot(q.a - p.a)) <= tolerance && std::abs(p.n.dot(q.b - p.a)) <= tolerance;
}

std::vector<Piece> BoundaryPieces(const std::vector<Rectangle>& rects,
                                  const GroundTruthParams& params) {
  const double tol = params.touch_tolerance_m;
  // Bounds grown beyond the clipping margin, so that every rectangle that can
  // cut an edge or cover a point is a candidate of it.
  std::vector<Box2> bounds;
  bounds.reserve(rects.size());
  for (const Rectangle& r : rects) bounds.push_back(BoundsOf(r, 2.0 * tol + 1e-9));
  const BoxGrid index(bounds);
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
      for (const int j : index.Candidates(a.cwiseMin(b), a.cwiseMax(b))) {
        if (j == static_cast<int>(i)) continue;
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
        for (const int j : index.Candidates(outside)) {
          covered = covered || (j != static_cast<int>(i) && rects[j].Contains(outside, 0.0));
        }
        if (!covered) pieces.push_back({a + cuts[k] * d, a + cuts[k + 1] * d, n});
      }
    }
  }
  return pieces;
}

namespace {

// Union-find root of k, with path halving.
int Root(std::vector<int>* parent, int k) {
  while ((*parent)[k] != k) {
    (*parent)[k] = (*parent)[(*parent)[k]];
    k = (*parent)[k];
  }
  return k;
}

// Groups of pieces on one line (SameLine, joined transitively), each in
// increasing order, the groups in order of their first piece. Candidates
// come from a hash of the line's direction and offset: pieces on one line
// differ by less than one bucket in each.
std::vector<std::vector<int>> LineGroups(const std::vector<Piece>& pieces, double tol) {
  const int n = static_cast<int>(pieces.size());
  // SameLine admits normals 4.5e-5 rad apart; offsets n . a then differ by
  // at most tol plus that angle times the distance from the origin.
  constexpr double kAngleBucket = 1e-4;
  const int num_angle_buckets = static_cast<int>(std::ceil(2.0 * M_PI / kAngleBucket));
  double radius = 0.0;
  for (const Piece& p : pieces) radius = std::max(radius, p.a.norm());
  const double offset_bucket = 2.0 * (tol + 5e-5 * radius) + 1e-9;
  std::vector<std::pair<long long, int>> keyed;
  std::vector<std::pair<int, long long>> cells(n);
  for (int k = 0; k < n; ++k) {
    double angle = std::atan2(pieces[k].n.y(), pieces[k].n.x());
    if (angle < 0.0) angle += 2.0 * M_PI;
    const int ka = std::min(num_angle_buckets - 1, static_cast<int>(angle / kAngleBucket));
    const long long ko = static_cast<long long>(std::floor(pieces[k].n.dot(pieces[k].a) /
                                                           offset_bucket));
    cells[k] = {ka, ko};
    keyed.push_back({ko * num_angle_buckets + ka, k});
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<int> parent(n);
  for (int k = 0; k < n; ++k) parent[k] = k;
  for (int i = 0; i < n; ++i) {
    for (int da = -1; da <= 1; ++da) {
      const int ka = (cells[i].first + da + num_angle_buckets) % num_angle_buckets;
      for (long long ko = cells[i].second - 1; ko <= cells[i].second + 1; ++ko) {
        const long long key = ko * num_angle_buckets + ka;
        auto it = std::lower_bound(keyed.begin(), keyed.end(), std::make_pair(key, -1));
        for (; it != keyed.end() && it->first == key; ++it) {
          const int j = it->second;
          if (j > i && SameLine(pieces[i], pieces[j], tol)) {
            parent[Root(&parent, j)] = Root(&parent, i);
          }
        }
      }
    }
  }
  std::vector<std::vector<int>> groups;
  std::vector<int> group_of_root(n, -1);
  for (int k = 0; k < n; ++k) {
    const int root = Root(&parent, k);
    if (group_of_root[root] < 0) {
      group_of_root[root] = static_cast<int>(groups.size());
      groups.emplace_back();
    }
    groups[group_of_root[root]].push_back(k);
  }
  return groups;
}

}  // namespace

std::vector<Piece> MergeCollinear(std::vector<Piece> pieces, const GroundTruthParams& params) {
  const double tol = params.touch_tolerance_m;
  // Merged pieces by the index of their first piece.
  std::vector<std::pair<int, Piece>> merged;
  for (const std::vector<int>& group : LineGroups(pieces, tol)) {
    // Positions along the line of the group's first piece, from its start.
    const Piece& first = pieces[group.front()];
    const Eigen::Vector2d d(-first.n.y(), first.n.x());  // direction a -> b
    struct Span {
      double s0;
      double s1;
      int index;
    };
    std::vector<Span> spans;
    for (const int k : group) {
      spans.push_back({d.dot(pieces[k].a - first.a), d.dot(pieces[k].b - first.a), k});
    }
    std::sort(spans.begin(), spans.end(), [](const Span& x, const Span& y) {
      return x.s0 != y.s0 ? x.s0 < y.s0 : x.index < y.index;
    });
    // Sweep: a span joins the run when it starts within 2 tol of its end.
    std::size_t k = 0;
    while (k < spans.size()) {
      Span start = spans[k];  // starts first (first index on ties)
      Span end = spans[k];    // ends last (first index on ties)
      int lowest = spans[k].index;
      for (++k; k < spans.size() && spans[k].s0 <= end.s1 + 2.0 * tol; ++k) {
        lowest = std::min(lowest, spans[k].index);
        if (spans[k].s0 == start.s0 && spans[k].index < start.index) start = spans[k];
        if (spans[k].s1 > end.s1 || (spans[k].s1 == end.s1 && spans[k].index < end.index)) {
          end = spans[k];
        }
      }
      merged.push_back({lowest, {pieces[start.index].a, pieces[end.index].b,
                                 pieces[lowest].n}});
    }
  }
  std::sort(merged.begin(), merged.end(),
            [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<Piece> segments;
  for (const auto& [index, p] : merged) {
    if ((p.b - p.a).norm() >= params.min_segment_length_m) segments.push_back(p);
  }
  return segments;
}

std::vector<int> NextSegments(const std::vector<Piece>& segments, double join_m) {
  std::vector<Box2> starts;
  starts.reserve(segments.size());
  for (const Piece& s : segments) starts.push_back({s.a, s.a});
  const BoxGrid index(starts);
  std::vector<int> next(segments.size(), -1);
  const Eigen::Vector2d reach = Eigen::Vector2d::Constant(join_m);
  for (std::size_t i = 0; i < segments.size(); ++i) {
    double best_distance = join_m;
    for (const int j : index.Candidates(segments[i].b - reach, segments[i].b + reach)) {
      if (j == static_cast<int>(i)) continue;
      const double distance = (segments[j].a - segments[i].b).norm();
      if (distance <= best_distance) {
        next[i] = j;
        best_distance = distance;
      }
    }
  }
  return next;
}

Grid2<std::uint8_t> OccupiedCells(const std::vector<Rectangle>& rects, const GridLimits& limits) {
  Grid2<std::uint8_t> occupied(limits, 0);
  for (const Rectangle& r : rects) {
    // The cells whose centres may lie in the rectangle's bounds, one more
    // each side for rounding.
    const Box2 box = BoundsOf(r, 0.0);
    const Eigen::Vector2i lo = limits.CellOf(box.lo);
    const Eigen::Vector2i hi = limits.CellOf(box.hi);
    for (int iy = std::max(0, lo.y() - 1); iy <= std::min(limits.height() - 1, hi.y() + 1);
         ++iy) {
      for (int ix = std::max(0, lo.x() - 1); ix <= std::min(limits.width() - 1, hi.x() + 1);
           ++ix) {
        if (!occupied(ix, iy) && r.Contains(limits.CellCenter(ix, iy), 0.0)) occupied(ix, iy) = 1;
      }
    }
  }
  return occupied;
}

}  // namespace detail

Map BuildGroundTruthMap(const std::vector<WallRectangle>& walls, const GroundTruthParams& params) {
  params.ValidateOrThrow();
  std::vector<detail::Rectangle> rects;
  for (std::size_t i = 0; i < walls.size(); ++i) {
    rects.push_back(
        detail::MakeRectangle(walls[i], static_cast<int>(i), params.min_segment_length_m));
  }
  std::vector<detail::Piece> segments =
      detail::MergeCollinear(detail::BoundaryPieces(rects, params), params);

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
  const std::vector<int> next = detail::NextSegments(segments, join);
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const int best = next[i];
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
  for (const detail::Piece& s : segments) {
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
  std::vector<detail::Rectangle> rects;
  for (std::size_t i = 0; i < walls.size(); ++i) {
    rects.push_back(detail::MakeRectangle(walls[i], static_cast<int>(i), 1e-9));
  }
  // The grid covers the walls, the start and the features, plus a margin
  // of two cells, so that the outside of a building is connected around it.
  Eigen::Vector2d lo = p_W_start;
  Eigen::Vector2d hi = p_W_start;
  for (const detail::Rectangle& r : rects) {
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
  const Grid2<std::uint8_t> occupied = detail::OccupiedCells(rects, limits);
  auto free_cell = [&](int ix, int iy) { return occupied(ix, iy) == 0; };
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
