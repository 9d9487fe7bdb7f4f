#include "explorer/occupancy_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/check.h"

namespace mjslam::explorer {
namespace {

// Margin added around the covered box when the grid grows, metres: growing by
// chunks keeps the number of reallocations small.
constexpr double kGrowthMarginM = 2.0;
// The most cells the grid grows to (400 MB of floats: 1 km x 1 km at 5 cm).
// A scan seen from a pose estimate far beyond any building asks for more.
constexpr double kMaxCells = 1e8;
// Largest shortening of a beam's free part at grazing incidence, metres.
constexpr double kMaxGrazingMarginM = 0.3;

}  // namespace

OccupancyGrid::OccupancyGrid(const ExplorerParams& params)
    : params_(params), limits_(Eigen::Vector2d::Zero(), params.grid_resolution_m, 0, 0) {}

double OccupancyGrid::LogOdds(int ix, int iy) const {
  return Contains(ix, iy) ? log_odds_[Index(ix, iy)] : 0.0;
}

CellState OccupancyGrid::StateAt(const Eigen::Vector2d& p_W) const {
  const Eigen::Vector2i c = CellOf(p_W);
  return State(c.x(), c.y());
}

double OccupancyGrid::KnownFreeArea() const {
  int count = 0;
  for (int iy = 0; iy < height(); ++iy) {
    for (int ix = 0; ix < width(); ++ix) count += State(ix, iy) == CellState::kFree;
  }
  return count * params_.grid_resolution_m * params_.grid_resolution_m;
}

void OccupancyGrid::EnsureCovers(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  const double r = params_.grid_resolution_m;
  const Eigen::Vector2d origin = limits_.origin();
  const int width = limits_.width();
  const int height = limits_.height();
  if (width > 0) {
    const Eigen::Vector2d top = limits_.far_corner();
    if (lo.x() >= origin.x() && lo.y() >= origin.y() && hi.x() < top.x() && hi.y() < top.y()) {
      return;
    }
  }
  const auto text = [](const Eigen::Vector2d& p) {
    return "(" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ")";
  };
  const Eigen::Vector2d reach_lo = width > 0 ? lo.cwiseMin(origin) : lo;
  const Eigen::Vector2d reach_hi = width > 0 ? hi.cwiseMax(limits_.far_corner()) : hi;
  const Eigen::Vector2d extent = reach_hi - reach_lo;
  if (!lo.allFinite() || !hi.allFinite() ||
      (extent.x() / r + 1.0) * (extent.y() / r + 1.0) > kMaxCells) {
    throw std::runtime_error("explorer: the occupancy grid cannot cover a scan from " + text(lo) +
                             " to " + text(hi) + " (beyond " + std::to_string(kMaxCells) +
                             " cells): the pose estimate it is driven from has left the world");
  }
  // New bounds on the existing cell lattice (origin moves by whole cells).
  Eigen::Vector2d new_lo = lo.array() - kGrowthMarginM;
  Eigen::Vector2d new_hi = hi.array() + kGrowthMarginM;
  if (width > 0) {
    new_lo = new_lo.cwiseMin(origin);
    new_hi = new_hi.cwiseMax(limits_.far_corner());
    const Eigen::Vector2d shift =
        ((origin - new_lo) / r).array().ceil().matrix() * r;  // whole cells
    new_lo = origin - shift;
  } else {
    new_lo = (new_lo / r).array().floor().matrix() * r;
  }
  const GridLimits grown_limits(
      new_lo, r, static_cast<int>(std::ceil((new_hi.x() - new_lo.x()) / r)) + 1,
      static_cast<int>(std::ceil((new_hi.y() - new_lo.y()) / r)) + 1);
  std::vector<float> grown(static_cast<size_t>(grown_limits.num_cells()), 0.0f);
  const int dx = static_cast<int>(std::lround((origin.x() - new_lo.x()) / r));
  const int dy = static_cast<int>(std::lround((origin.y() - new_lo.y()) / r));
  for (int iy = 0; iy < height; ++iy) {
    for (int ix = 0; ix < width; ++ix) {
      grown[grown_limits.Index(ix + dx, iy + dy)] = log_odds_[Index(ix, iy)];
    }
  }
  log_odds_.swap(grown);
  limits_ = grown_limits;
  if (width > 0) {
    lattice_origin_ -= Eigen::Vector2i(dx, dy);
  } else {
    lattice_origin_ = Eigen::Vector2i(static_cast<int>(std::lround(new_lo.x() / r)),
                                      static_cast<int>(std::lround(new_lo.y() / r)));
  }
  marks_.assign(log_odds_.size(), 0);
  touched_.clear();
}

void OccupancyGrid::MarkFree(int index) {
  if (marks_[index] == 0) {
    marks_[index] = 1;
    touched_.push_back(index);
  }
}

void OccupancyGrid::MarkRayFree(const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  // Every cell the segment crosses, once.
  TraverseSegment(limits_, from, to, [this](int ix, int iy) {
    if (Contains(ix, iy)) MarkFree(Index(ix, iy));
  });
}

void OccupancyGrid::ApplyMarks() {
  // The box of the cells whose state changes (empty while lo > hi).
  LatticeBox changed{Eigen::Vector2i::Constant(std::numeric_limits<int>::max()),
                     Eigen::Vector2i::Constant(std::numeric_limits<int>::min())};
  for (const int i : touched_) {
    const double delta = marks_[i] == 2 ? params_.log_odds_hit : params_.log_odds_miss;
    const CellState was = StateOfLogOdds(log_odds_[i]);
    log_odds_[i] = static_cast<float>(std::clamp(log_odds_[i] + delta, params_.log_odds_min,
                                                 params_.log_odds_max));
    marks_[i] = 0;
    const CellState is = StateOfLogOdds(log_odds_[i]);
    if (is == was) continue;
    const Eigen::Vector2i lattice = limits_.CellOfIndex(i) + lattice_origin_;
    changed.lo = changed.lo.cwiseMin(lattice);
    changed.hi = changed.hi.cwiseMax(lattice);
    // The log of occupancy changes (read by ClearanceField).
    if ((is == CellState::kOccupied) != (was == CellState::kOccupied)) {
      occupancy_changes_.push_back(lattice);
    }
  }
  touched_.clear();
  if (changed.lo.x() <= changed.hi.x()) state_changes_.push_back(changed);
}

OccupancyGrid::BeamFreeSpace OccupancyGrid::FreeSpaceOfBeams(const LaserScan& scan) const {
  const int n = scan.size();
  const double r_cell = params_.grid_resolution_m;
  BeamFreeSpace beams;
  beams.free_range_m.resize(n);
  beams.hit.resize(n);
  auto echo_at = [&](int i) {
    return i >= 0 && i < n && scan.has_return[i] != 0 && scan.ranges_m[i] < scan.max_range_m;
  };
  for (int i = 0; i < n; ++i) {
    const bool echo = echo_at(i);
    if (echo && scan.ranges_m[i] <= params_.max_insert_range_m) {
      // Stop short of the surface by more at grazing incidence, so that the
      // beam does not run along the row of cells holding the wall and erase
      // it: 0.7 cell across the surface, whose direction comes from the
      // neighbouring echo at a similar range.
      double margin = 0.5 * r_cell;
      for (const int j : {i + 1, i - 1}) {
        if (!echo_at(j) || std::abs(scan.ranges_m[j] - scan.ranges_m[i]) > 0.5) continue;
        const double a_i = scan.BeamAngle(i);
        const double a_j = scan.BeamAngle(j);
        const Eigen::Vector2d u(std::cos(a_i), std::sin(a_i));
        const Eigen::Vector2d tangent =
            scan.ranges_m[j] * Eigen::Vector2d(std::cos(a_j), std::sin(a_j)) -
            scan.ranges_m[i] * u;
        if (tangent.norm() < 1e-9) break;
        const double sin_incidence =
            std::abs(u.x() * tangent.y() - u.y() * tangent.x()) / tangent.norm();
        margin = std::max(margin, std::min(kMaxGrazingMarginM,
                                           0.7 * r_cell / std::max(sin_incidence, 1e-3)));
        break;
      }
      beams.free_range_m[i] = std::max(0.0, scan.ranges_m[i] - margin);
      beams.hit[i] = 1;
    } else if (echo) {
      beams.free_range_m[i] = params_.max_insert_range_m;
      beams.hit[i] = 0;
    } else {
      beams.free_range_m[i] =
          std::min(params_.no_return_free_range_m, params_.max_insert_range_m);
      beams.hit[i] = 0;
    }
  }
  return beams;
}

void OccupancyGrid::CoverScan(const LaserScan& scan, const Pose2& X_WS,
                              const BeamFreeSpace& beams) {
  const Eigen::Vector2d p_WS = X_WS.translation();
  Eigen::Vector2d lo = p_WS;
  Eigen::Vector2d hi = p_WS;
  for (int i = 0; i < scan.size(); ++i) {
    const double th = X_WS.theta + scan.BeamAngle(i);
    const double range = beams.hit[i] ? scan.ranges_m[i] : beams.free_range_m[i];
    const Eigen::Vector2d p = p_WS + range * Eigen::Vector2d(std::cos(th), std::sin(th));
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  EnsureCovers(lo, hi);
}

void OccupancyGrid::MarkScanFree(const LaserScan& scan, const Pose2& X_WS,
                                 const BeamFreeSpace& beams) {
  const int n = scan.size();
  const double r_cell = params_.grid_resolution_m;
  const Eigen::Vector2d p_WS = X_WS.translation();
  const std::vector<double>& free_range = beams.free_range_m;
  for (int i = 0; i < n; ++i) {
    const double th = X_WS.theta + scan.BeamAngle(i);
    MarkRayFree(p_WS, p_WS + free_range[i] * Eigen::Vector2d(std::cos(th), std::sin(th)));
    if (i + 1 == n) break;
    const double range = std::min(free_range[i], free_range[i + 1]) - 0.5 * r_cell;
    if (range <= 0.0) continue;
    const int sub = static_cast<int>(std::ceil(range * std::abs(scan.angle_increment_rad) /
                                               (0.7 * r_cell)));
    for (int k = 1; k < sub; ++k) {
      const double th_k = th + scan.angle_increment_rad * double(k) / sub;
      MarkRayFree(p_WS, p_WS + range * Eigen::Vector2d(std::cos(th_k), std::sin(th_k)));
    }
  }
}

void OccupancyGrid::MarkEchoesOccupied(const LaserScan& scan, const Pose2& X_WS,
                                       const BeamFreeSpace& beams) {
  const Eigen::Vector2d p_WS = X_WS.translation();
  for (int i = 0; i < scan.size(); ++i) {
    if (!beams.hit[i]) continue;
    const double th = X_WS.theta + scan.BeamAngle(i);
    const Eigen::Vector2i c =
        CellOf(p_WS + scan.ranges_m[i] * Eigen::Vector2d(std::cos(th), std::sin(th)));
    if (!Contains(c.x(), c.y())) continue;
    const int index = Index(c.x(), c.y());
    if (marks_[index] == 0) touched_.push_back(index);
    marks_[index] = 2;
  }
}

void OccupancyGrid::InsertScan(const LaserScan& scan, const Pose2& X_WS) {
  if (scan.size() == 0) return;
  const BeamFreeSpace beams = FreeSpaceOfBeams(scan);
  CoverScan(scan, X_WS, beams);
  MarkScanFree(scan, X_WS, beams);
  MarkEchoesOccupied(scan, X_WS, beams);
  ApplyMarks();
}

void OccupancyGrid::MarkRectangleFree(const Pose2& X_WB, double x0_m, double x1_m,
                                      double half_width_m) {
  const Pose2 X_BW = X_WB.Inverse();
  Eigen::Vector2d lo = X_WB.translation();
  Eigen::Vector2d hi = lo;
  for (const double x : {x0_m, x1_m}) {
    for (const double y : {-half_width_m, half_width_m}) {
      const Eigen::Vector2d p = X_WB * Eigen::Vector2d(x, y);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  EnsureCovers(lo, hi);
  const Eigen::Vector2i c0 = CellOf(lo);
  const Eigen::Vector2i c1 = CellOf(hi);
  for (int iy = c0.y(); iy <= c1.y(); ++iy) {
    for (int ix = c0.x(); ix <= c1.x(); ++ix) {
      const Eigen::Vector2d p_B = X_BW * CellCenter(ix, iy);
      if (p_B.x() < x0_m || p_B.x() > x1_m || std::abs(p_B.y()) > half_width_m) continue;
      MarkFree(Index(ix, iy));
    }
  }
  ApplyMarks();
}

}  // namespace mjslam::explorer
