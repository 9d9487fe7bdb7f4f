#include "sim/local_geoms.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <mujoco/mujoco.h>

#include "common/check.h"
#include "common/grid2.h"

namespace mjslam::sim::internal {
namespace {

// Cell size of the grid, metres: walls are metres long and beams up to 30 m,
// so a beam crosses tens of cells and a cell lists a few geoms. (0.5, 1 and
// 2 m cost about the same in the shipped and generated worlds.)
constexpr double kCellM = 1.0;
// Boxes are widened by this much, metres, and a beam stops only this far
// before the exit of the cell it has reached: floating-point errors in the
// cell traversal (about 1e-14 m) cannot lose a geom.
constexpr double kRoundingM = 1e-6;
// How far the robot may move between refreshes of the contact candidates,
// metres, and the extra radius beyond its reach (margins, rounding).
constexpr double kContactSlackM = 0.25;
constexpr double kContactExtraM = 0.1;

// mj_ray's eligibility of a geom (its ray_eliminate with flg_static = 1 and
// no body excluded): invisible geoms and geoms with an invisible material
// are skipped; planes and height fields are looked at whatever their group;
// other geoms if their group (clamped to [0, mjNGROUP)) is in the mask.
bool RayEligible(const mjModel& m, int geom, const mjtByte* geomgroup) {
  const int material = m.geom_matid[geom];
  if (material < 0 && m.geom_rgba[4 * geom + 3] == 0) return false;
  if (material >= 0 && m.mat_rgba[4 * material + 3] == 0) return false;
  const int type = m.geom_type[geom];
  if (type == mjGEOM_PLANE || type == mjGEOM_HFIELD) return true;
  if (geomgroup == nullptr) return true;
  const int group = std::min(mjNGROUP - 1, std::max(0, m.geom_group[geom]));
  return geomgroup[group] != 0;
}

// The floor-plane bounding box of a geom at its current pose: exact for a
// box (|R| times the half sizes), the bounding sphere otherwise; widened by
// kRoundingM.
Box2 FootprintBox(const mjModel& m, const mjData& d, int geom) {
  const mjtNum* p = d.geom_xpos + 3 * geom;
  const mjtNum* R = d.geom_xmat + 9 * geom;
  const mjtNum* size = m.geom_size + 3 * geom;
  Eigen::Vector2d half;
  if (m.geom_type[geom] == mjGEOM_BOX) {
    for (int row = 0; row < 2; ++row) {
      half[row] = std::abs(R[3 * row]) * size[0] + std::abs(R[3 * row + 1]) * size[1] +
                  std::abs(R[3 * row + 2]) * size[2];
    }
  } else {
    half.setConstant(m.geom_rbound[geom]);
  }
  half.array() += kRoundingM;
  Box2 box;
  box.lo = Eigen::Vector2d(p[0], p[1]) - half;
  box.hi = Eigen::Vector2d(p[0], p[1]) + half;
  return box;
}

}  // namespace

LocalGeoms::LocalGeoms(const mjModel& m, const mjData& d, const RobotIndices& ids,
                       const mjtByte* geomgroup) {
  // Static world geoms into the grid; the rest that rays see, always.
  std::vector<Box2> boxes;
  double world_margin = 0.0;
  for (int geom = 0; geom < m.ngeom; ++geom) {
    const int type = m.geom_type[geom];
    const bool is_static = m.body_weldid[m.geom_bodyid[geom]] == 0;
    const bool ray = RayEligible(m, geom, geomgroup);
    if (!is_static || type == mjGEOM_PLANE || type == mjGEOM_HFIELD) {
      if (ray) always_ray_.push_back(geom);
      continue;
    }
    static_geom_.push_back(geom);
    ray_eligible_.push_back(ray ? 1 : 0);
    contype_.push_back(m.geom_contype[geom]);
    conaffinity_.push_back(m.geom_conaffinity[geom]);
    sameframe_.push_back(m.geom_sameframe[geom]);
    xpos_.insert(xpos_.end(), d.geom_xpos + 3 * geom, d.geom_xpos + 3 * geom + 3);
    xmat_.insert(xmat_.end(), d.geom_xmat + 9 * geom, d.geom_xmat + 9 * geom + 9);
    boxes.push_back(FootprintBox(m, d, geom));
    world_margin = std::max(world_margin, static_cast<double>(m.geom_margin[geom]));
  }
  grid_ = BoxGrid(std::move(boxes), kCellM);
  for (int site = 0; site < m.nsite; ++site) {
    if (m.body_weldid[m.site_bodyid[site]] != 0) continue;
    static_site_.push_back(site);
    site_sameframe_.push_back(m.site_sameframe[site]);
    site_xpos_.insert(site_xpos_.end(), d.site_xpos + 3 * site, d.site_xpos + 3 * site + 3);
    site_xmat_.insert(site_xmat_.end(), d.site_xmat + 9 * site, d.site_xmat + 9 * site + 9);
  }
  ray_stamp_.assign(static_geom_.size(), 0);

  // The robot's reach from its root body: each colliding geom's bounding
  // sphere (and margin) around the root's origin.
  const mjtNum* root = d.xpos + 3 * ids.root_body;
  double reach = 0.0;
  for (int geom = 0; geom < m.ngeom; ++geom) {
    if (!IsRobotGeom(m, ids, geom)) continue;
    if (m.geom_contype[geom] == 0 && m.geom_conaffinity[geom] == 0) continue;
    MJSLAM_CHECK(m.geom_rbound[geom] > 0.0);  // no plane on the robot
    const mjtNum* p = d.geom_xpos + 3 * geom;
    const double distance = std::sqrt((p[0] - root[0]) * (p[0] - root[0]) +
                                      (p[1] - root[1]) * (p[1] - root[1]) +
                                      (p[2] - root[2]) * (p[2] - root[2]));
    reach = std::max(reach, distance + m.geom_rbound[geom] + m.geom_margin[geom]);
  }
  slack_m_ = kContactSlackM;
  contact_radius_m_ = reach + world_margin + kContactSlackM + kContactExtraM;
  max_contact_candidates_ = CountMaxContactCandidates();
}

int LocalGeoms::CountMaxContactCandidates() const {
  if (grid_.num_boxes() == 0) return 0;
  // A disc of the radius around a point in cell c (or outside the grid,
  // nearest to c) reaches only cells within `reach` cells of c on each axis.
  const GridLimits& limits = grid_.limits();
  const int reach = static_cast<int>(std::ceil(contact_radius_m_ / limits.resolution()));
  std::vector<int> stamp(static_geom_.size(), -1);
  int most = 0;
  for (int cy = 0; cy < limits.height(); ++cy) {
    for (int cx = 0; cx < limits.width(); ++cx) {
      const int cell = limits.Index(cx, cy);
      int count = 0;
      for (int iy = std::max(0, cy - reach); iy <= std::min(limits.height() - 1, cy + reach); ++iy) {
        for (int ix = std::max(0, cx - reach); ix <= std::min(limits.width() - 1, cx + reach);
             ++ix) {
          for (const int* id = grid_.CellBegin(ix, iy); id != grid_.CellEnd(ix, iy); ++id) {
            if (stamp[*id] == cell || (contype_[*id] == 0 && conaffinity_[*id] == 0)) continue;
            stamp[*id] = cell;
            ++count;
          }
        }
      }
      most = std::max(most, count);
    }
  }
  return most;
}

mjtNum LocalGeoms::RayGeom(const mjModel& m, const mjData& d, int geom, int box,
                           const mjtNum pnt[3], const mjtNum vec[3]) const {
  switch (m.geom_type[geom]) {
    case mjGEOM_MESH:
      return mj_rayMesh(&m, &d, geom, pnt, vec);
    case mjGEOM_HFIELD:
      return mj_rayHfield(&m, &d, geom, pnt, vec);
    default:
      if (box >= 0) {
        return mju_rayGeom(xpos_.data() + 3 * box, xmat_.data() + 9 * box,
                           m.geom_size + 3 * geom, pnt, vec, m.geom_type[geom]);
      }
      return mju_rayGeom(d.geom_xpos + 3 * geom, d.geom_xmat + 9 * geom, m.geom_size + 3 * geom,
                         pnt, vec, m.geom_type[geom]);
  }
}

// A mesh keeps its pose computed (mj_rayMesh reads it from mjData).
void LocalGeoms::SetActive(mjModel* m, int id, bool active) const {
  const int geom = static_geom_[id];
  m->geom_contype[geom] = active ? contype_[id] : 0;
  m->geom_conaffinity[geom] = active ? conaffinity_[id] : 0;
  if (m->geom_type[geom] != mjGEOM_MESH) m->geom_sameframe[geom] = active ? sameframe_[id] : 1;
}

mjtNum LocalGeoms::CastRay(const mjModel& m, const mjData& d, const mjtNum pnt[3],
                           const mjtNum vec[3], double max_range) const {
  // The nearest of mj_ray's candidates, as mj_ray keeps it.
  mjtNum distance = -1;
  const auto consider = [&](int geom, int box) {
    const mjtNum candidate = RayGeom(m, d, geom, box, pnt, vec);
    if (candidate >= 0 && (candidate < distance || distance < 0)) distance = candidate;
  };
  for (const int geom : always_ray_) consider(geom, -1);
  if (grid_.num_boxes() == 0) return distance;

  // A new stamp for this ray (on wrap-around, all stamps are cleared).
  if (++ray_count_ == 0) {
    std::fill(ray_stamp_.begin(), ray_stamp_.end(), 0);
    ray_count_ = 1;
  }
  // The static geoms of the cells along the ray, in order, until a hit lies
  // before the exit of the cell reached: a nearer hit would lie in a cell
  // already visited (a geom is listed in every cell its box touches).
  const GridLimits& limits = grid_.limits();
  const double r = limits.resolution();
  const double inf = std::numeric_limits<double>::infinity();
  const Eigen::Vector2d p(pnt[0], pnt[1]);
  const Eigen::Vector2d u(vec[0], vec[1]);
  bool done = false;
  TraverseSegment(limits, p, p + max_range * u, [&](int ix, int iy) {
    if (done || !limits.Contains(ix, iy)) return;
    for (const int* id = grid_.CellBegin(ix, iy); id != grid_.CellEnd(ix, iy); ++id) {
      if (ray_stamp_[*id] == ray_count_) continue;
      ray_stamp_[*id] = ray_count_;
      if (ray_eligible_[*id]) consider(static_geom_[*id], *id);
    }
    const Eigen::Vector2d corner = limits.origin() + r * Eigen::Vector2d(ix, iy);
    const double t_x = u.x() > 0 ? (corner.x() + r - p.x()) / u.x()
                       : u.x() < 0 ? (corner.x() - p.x()) / u.x()
                                   : inf;
    const double t_y = u.y() > 0 ? (corner.y() + r - p.y()) / u.y()
                       : u.y() < 0 ? (corner.y() - p.y()) / u.y()
                                   : inf;
    if (distance >= 0 && distance <= std::min(t_x, t_y) - kRoundingM) done = true;
  });
  return distance;
}

void LocalGeoms::FilterContacts(mjModel* m, const mjtNum* p_root) {
  const bool first = !refresh_.done();
  if (!refresh_.Due(p_root, slack_m_)) return;
  // Off: every static geom and site (the first time) or the geoms enabled
  // until now.
  if (first) {
    for (int id = 0; id < static_cast<int>(static_geom_.size()); ++id) SetActive(m, id, false);
    for (const int site : static_site_) m->site_sameframe[site] = 1;
  }
  for (const int id : enabled_) SetActive(m, id, false);
  // On: those within the radius of the robot's root, with their own values.
  enabled_.clear();
  ForEachCandidateBox(Eigen::Vector2d(p_root[0], p_root[1]), [&](int id) {
    SetActive(m, id, true);
    enabled_.push_back(id);
  });
}

void LocalGeoms::RestoreContacts(mjModel* m, mjData* d) {
  for (int id = 0; id < static_cast<int>(static_geom_.size()); ++id) {
    SetActive(m, id, true);
    const int geom = static_geom_[id];
    std::copy_n(xpos_.data() + 3 * id, 3, d->geom_xpos + 3 * geom);
    std::copy_n(xmat_.data() + 9 * id, 9, d->geom_xmat + 9 * geom);
  }
  for (std::size_t k = 0; k < static_site_.size(); ++k) {
    const int site = static_site_[k];
    m->site_sameframe[site] = site_sameframe_[k];
    std::copy_n(site_xpos_.data() + 3 * k, 3, d->site_xpos + 3 * site);
    std::copy_n(site_xmat_.data() + 9 * k, 9, d->site_xmat + 9 * site);
  }
  enabled_.clear();
  refresh_.Reset();
}

}  // namespace mjslam::sim::internal
