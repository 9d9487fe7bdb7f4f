#pragma once

// Internal to sim/ (it includes MuJoCo; tests/layering_test.cc keeps it in
// sim/): the world's static geoms in a BoxGrid, so that the simulator's
// contacts and laser beams consider only the geoms near the robot or along
// the beam, with MuJoCo's own per-geom functions: the answers are MuJoCo's,
// the cost local. See sim/README.md, "Local contacts and beams".

#include <cmath>
#include <vector>

#include <mujoco/mujoco.h>

#include "common/box_grid.h"
#include "sim/scene_model.h"

namespace mjslam::sim::internal {

/// When the contact candidates around the robot must be found again: at the
/// first call, when forced, and once the robot's root has moved more than a
/// slack from where they were last found (in the floor plane).
class ContactRefresh {
 public:
  /// Whether a refresh is due at root position `p_root` (x, y) with
  /// `slack_m`; if so, `p_root` becomes the point of the last refresh.
  bool Due(const mjtNum* p_root, double slack_m, bool force = false) {
    if (!force && done_ && std::hypot(p_root[0] - x_, p_root[1] - y_) <= slack_m) return false;
    done_ = true;
    x_ = p_root[0];
    y_ = p_root[1];
    return true;
  }
  /// Forgets the last refresh (the next call is due).
  void Reset() { done_ = false; }
  /// Whether there has been a refresh since construction or Reset.
  bool done() const { return done_; }

 private:
  bool done_ = false;
  double x_ = 0.0;
  double y_ = 0.0;
};

/// The geoms of a composed scene that mj_ray and mj_collision would look at,
/// split into the static ones of the world (body welded to the world, not a
/// plane or height field), gridded by their floor-plane bounding boxes, and
/// the rest (planes, height fields, geoms on moving bodies other than the
/// robot), always looked at.
///
/// Rays (CastRay) return what mj_ray(m, d, pnt, vec, geomgroup, flg_static =
/// 1, bodyexclude = -1) returns for horizontal rays up to a range, bit for
/// bit: the same eligibility rules as mj_ray (group mask, invisible geoms and
/// materials skipped, planes and height fields whatever their group) and the
/// same per-geom functions (mju_rayGeom, mj_rayMesh, mj_rayHfield), the
/// smallest distance over the geoms the ray's cells list.
///
/// Contacts (FilterContacts): the static world geoms farther than a radius
/// from the robot get contype = conaffinity = 0 in the simulator's own model
/// copy, the others keep their values; refreshed whenever the robot has
/// moved more than a slack since the last refresh, so that every geom the
/// robot can reach before the next refresh keeps colliding. MuJoCo then
/// produces the same contacts (a pair it skips is one that could not touch).
/// The far primitive geoms and every static site also get sameframe = 1, so
/// that mj_kinematics copies the world frame into their poses instead of
/// recomputing them on every step: their poses in mjData are then wrong,
/// and nothing reads them (they do not collide, the laser reads the static
/// poses kept at construction, the simulator reads only the robot's sites).
class LocalGeoms {
 public:
  /// Grids the static geoms of (m, d) (kinematics computed: geom_xpos and
  /// geom_xmat valid; their poses are kept) for rays masked by `geomgroup`
  /// (mjNGROUP flags, as mj_ray's) and for contacts with the robot `ids`.
  /// Reads the robot's reach from the current state: the largest distance
  /// from the robot's root body to the bounding sphere of any of its
  /// colliding geoms. Changes nothing in `m` until FilterContacts.
  LocalGeoms(const mjModel& m, const mjData& d, const RobotIndices& ids,
             const mjtByte* geomgroup);

  /// The distance along `vec` (unit, horizontal: vec[2] == 0) from `pnt` to
  /// the nearest eligible geom, as mj_ray; -1 when none is hit before
  /// `max_range` (a hit at or beyond max_range may or may not be returned:
  /// callers compare with max_range). Not thread-safe (a per-ray stamp).
  mjtNum CastRay(const mjModel& m, const mjData& d, const mjtNum pnt[3], const mjtNum vec[3],
                 double max_range) const;

  /// Makes only the static world geoms within reach of the robot at
  /// root position `p_root` (x, y, the position the next mj_step collides
  /// at) candidates for contacts in `m` (see the class comment); a no-op
  /// while the robot is within the slack of the last refresh. `m` must be
  /// the model LocalGeoms was built from.
  void FilterContacts(mjModel* m, const mjtNum* p_root);
  /// Gives every static world geom back its own contype, conaffinity and
  /// sameframe, and every static site its sameframe (MuJoCo's all-pairs
  /// collision, every pose computed), and writes the static geoms' and
  /// sites' poses kept at construction back into `d` (what mj_kinematics
  /// would compute for them); FilterContacts starts again from scratch at
  /// its next call.
  void RestoreContacts(mjModel* m, mjData* d);

  /// The radius around the robot's root at a refresh within which static
  /// geoms are contact candidates, and how far the root may move before the
  /// next refresh, metres (see the class comment).
  double contact_radius_m() const { return contact_radius_m_; }
  double contact_slack_m() const { return slack_m_; }
  /// Calls visit(geom) with the model id of each static world geom that can
  /// collide (contype or conaffinity not 0) whose box lies within
  /// contact_radius_m() of `p`, in increasing id order (planes and height
  /// fields are not in the grid: never visited).
  template <typename Visit>
  void ForEachContactCandidate(const Eigen::Vector2d& p, const Visit& visit) const {
    ForEachCandidateBox(p, [&](int id) { visit(static_geom_[id]); });
  }
  /// An upper bound on the number of geoms ForEachContactCandidate visits,
  /// wherever the point: the largest number of colliding geoms listed in
  /// the block of cells around any cell that a disc of contact_radius_m()
  /// can reach.
  int MaxContactCandidates() const { return max_contact_candidates_; }

 private:
  // mj_ray's per-geom distance: mesh, height field or primitive (a static
  // primitive at the pose kept at construction, `box` its id; -1 if none).
  mjtNum RayGeom(const mjModel& m, const mjData& d, int geom, int box, const mjtNum pnt[3],
                 const mjtNum vec[3]) const;
  // Calls visit(id) for each colliding box within contact_radius_m_ of p,
  // in increasing id order.
  template <typename Visit>
  void ForEachCandidateBox(const Eigen::Vector2d& p, const Visit& visit) const {
    grid_.ForEachNear(p, contact_radius_m_, [&](int id) {
      if (contype_[id] != 0 || conaffinity_[id] != 0) visit(id);
    });
  }
  // The bound of MaxContactCandidates.
  int CountMaxContactCandidates() const;
  // Turns box `id`'s contacts and pose computation off or back on.
  void SetActive(mjModel* m, int id, bool active) const;

  BoxGrid grid_;
  // Box id -> geom id; and whether that geom is eligible for rays.
  std::vector<int> static_geom_;
  std::vector<unsigned char> ray_eligible_;
  // The geom's own contype and conaffinity (static geoms, by box id).
  std::vector<int> contype_;
  std::vector<int> conaffinity_;
  std::vector<mjtByte> sameframe_;
  // The static geoms' poses (3 and 9 numbers per box id), as computed by
  // MuJoCo at construction.
  std::vector<mjtNum> xpos_;
  std::vector<mjtNum> xmat_;
  // The static sites, their own sameframe and their poses at construction.
  std::vector<int> static_site_;
  std::vector<mjtByte> site_sameframe_;
  std::vector<mjtNum> site_xpos_;
  std::vector<mjtNum> site_xmat_;
  // Geoms looked at on every ray (planes, height fields, moving geoms).
  std::vector<int> always_ray_;
  // The per-ray stamp of each box (a box spans several cells).
  mutable std::vector<unsigned> ray_stamp_;
  mutable unsigned ray_count_ = 0;
  // Contacts: the radius around the refresh point, the slack, the refresh
  // point, the box ids now enabled.
  double contact_radius_m_ = 0.0;
  double slack_m_ = 0.0;
  ContactRefresh refresh_;
  std::vector<int> enabled_;
  int max_contact_candidates_ = 0;
};

}  // namespace mjslam::sim::internal
