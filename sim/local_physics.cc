#include "sim/local_physics.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <type_traits>

#include <mujoco/mjxmacro.h>

#include "common/check.h"
#include "sim/mujoco_errors.h"

namespace mjslam::sim::internal {
namespace {

bool IsStatic(const mjModel& m, int geom) { return m.body_weldid[m.geom_bodyid[geom]] == 0; }
bool Collides(const mjModel& m, int geom) {
  return m.geom_contype[geom] != 0 || m.geom_conaffinity[geom] != 0;
}

// The first robot row of each kind (the robot is composed last, so its
// bodies, geoms and sites are the last rows of their arrays).
struct RobotRows {
  int body = 0;
  int geom = 0;
  int site = 0;
};

RobotRows FindRobotRows(const mjModel& m, const RobotIndices& ids) {
  RobotRows rows{ids.root_body, m.ngeom, m.nsite};
  for (int geom = m.ngeom - 1; geom >= 0 && IsRobotGeom(m, ids, geom); --geom) rows.geom = geom;
  for (int site = m.nsite - 1;
       site >= 0 && m.body_rootid[m.site_bodyid[site]] == ids.root_body; --site) {
    rows.site = site;
  }
  return rows;
}

// The first floating-point array of the robot's rows that differs between
// the two models ("" if none): bodies, geoms and sites from the robot's
// first row on; joints, dofs, actuators and qpos arrays whole (the world has
// none). User arrays are left out.
std::string FirstRobotDifference(const mjModel& full, const RobotIndices& full_ids,
                                 const mjModel& local, const RobotIndices& local_ids) {
  const RobotRows f = FindRobotRows(full, full_ids);
  const RobotRows l = FindRobotRows(local, local_ids);
  if (full.nbody - f.body != local.nbody - l.body || full.ngeom - f.geom != local.ngeom - l.geom ||
      full.nsite - f.site != local.nsite - l.site || full.nq != local.nq || full.nv != local.nv ||
      full.na != local.na || full.nu != local.nu || full.njnt != local.njnt) {
    return "the number of robot bodies, geoms, sites, joints, dofs or actuators";
  }
  std::string difference;
  const auto compare = [&](const char* name, const std::string& rows, const auto* a,
                           const auto* b, int columns) {
    using Type = std::remove_cv_t<std::remove_pointer_t<decltype(a)>>;
    if constexpr (!std::is_same_v<Type, mjtNum>) return;
    if (!difference.empty() || std::strstr(name, "_user") != nullptr) return;
    int first_a = 0, first_b = 0, count = 0;
    if (rows == "nbody") {
      first_a = f.body, first_b = l.body, count = full.nbody - f.body;
    } else if (rows == "ngeom") {
      first_a = f.geom, first_b = l.geom, count = full.ngeom - f.geom;
    } else if (rows == "nsite") {
      first_a = f.site, first_b = l.site, count = full.nsite - f.site;
    } else if (rows == "nq" || rows == "nv" || rows == "na" || rows == "nu" || rows == "njnt") {
      count = rows == "nq" ? full.nq : rows == "nv" ? full.nv : rows == "na" ? full.na
              : rows == "nu" ? full.nu : full.njnt;
    } else {
      return;
    }
    if (std::memcmp(a + first_a * columns, b + first_b * columns,
                    sizeof(Type) * count * columns) != 0) {
      difference = name;
    }
  };
  const mjModel* m = &full;
  MJMODEL_POINTERS_PREAMBLE(m)
#define X(type, name, nr, nc) compare(#name, #nr, full.name, local.name, static_cast<int>(nc));
  MJMODEL_POINTERS
#undef X
  (void)nuser_body, (void)nuser_jnt, (void)nuser_geom, (void)nuser_site, (void)nuser_cam,
      (void)nuser_tendon, (void)nuser_actuator, (void)nuser_sensor, (void)nq, (void)nv, (void)na,
      (void)nu, (void)nmocap;
  return difference;
}

// Every field of geom `from` of `full` that collision reads, into geom
// `slot` of `local` (both on the world body).
void CopyGeom(const mjModel& full, int from, mjModel* local, int slot) {
  local->geom_type[slot] = full.geom_type[from];
  local->geom_contype[slot] = full.geom_contype[from];
  local->geom_conaffinity[slot] = full.geom_conaffinity[from];
  local->geom_condim[slot] = full.geom_condim[from];
  local->geom_dataid[slot] = -1;
  local->geom_matid[slot] = -1;
  local->geom_group[slot] = full.geom_group[from];
  local->geom_priority[slot] = full.geom_priority[from];
  local->geom_sameframe[slot] = full.geom_sameframe[from];
  local->geom_solmix[slot] = full.geom_solmix[from];
  const auto copy = [&](const mjtNum* source, mjtNum* target, int n) {
    std::copy_n(source + n * from, n, target + n * slot);
  };
  copy(full.geom_solref, local->geom_solref, mjNREF);
  copy(full.geom_solimp, local->geom_solimp, mjNIMP);
  copy(full.geom_size, local->geom_size, 3);
  copy(full.geom_rbound, local->geom_rbound, 1);
  copy(full.geom_pos, local->geom_pos, 3);
  copy(full.geom_quat, local->geom_quat, 4);
  copy(full.geom_friction, local->geom_friction, 3);
  copy(full.geom_margin, local->geom_margin, 1);
  copy(full.geom_gap, local->geom_gap, 1);
  copy(full.geom_fluid, local->geom_fluid, mjNFLUID);
  std::copy_n(full.geom_rgba + 4 * from, 4, local->geom_rgba + 4 * slot);
}

// A slot that collides with nothing and whose pose is the world's (a copy).
void FreeSlot(mjModel* local, int slot) {
  local->geom_contype[slot] = 0;
  local->geom_conaffinity[slot] = 0;
  local->geom_type[slot] = mjGEOM_SPHERE;
  local->geom_sameframe[slot] = 1;
  local->geom_rbound[slot] = 0.001;
  std::fill_n(local->geom_size + 3 * slot, 3, 0.001);
  std::fill_n(local->geom_pos + 3 * slot, 3, 0.0);
  const mjtNum identity[4] = {1, 0, 0, 0};
  std::copy_n(identity, 4, local->geom_quat + 4 * slot);
}

// MuJoCo 2.2.2's contact filter (mj_contactFilter, as mj_collideGeoms calls
// it for a geom pair it found itself): whether geoms g1 and g2 of `m` never
// make contacts with each other.
bool Filtered(const mjModel& m, int g1, int g2) {
  if (!(m.geom_contype[g1] & m.geom_conaffinity[g2]) &&
      !(m.geom_contype[g2] & m.geom_conaffinity[g1])) {
    return true;
  }
  const int weld1 = m.body_weldid[m.geom_bodyid[g1]];
  const int weld2 = m.body_weldid[m.geom_bodyid[g2]];
  if (weld1 == weld2) return true;
  const bool filter_parent = !(m.opt.disableflags & mjDSBL_FILTERPARENT) && weld1 && weld2;
  return filter_parent && (weld1 == m.body_weldid[m.body_parentid[weld2]] ||
                           weld2 == m.body_weldid[m.body_parentid[weld1]]);
}

// Makes pair `pair` of `m` the geom pair (g1, g2) with the contact
// parameters MuJoCo 2.2.2's mj_collideGeoms gives a pair it finds itself
// (priority or maximum for condim and friction, the solmix mixture of solref
// and solimp, the largest margin and gap): the same operations on the same
// numbers in the same order (the geoms ordered by type first, as there), so
// the contacts of the pair are the same, bit for bit.
void SetPairAsFound(mjModel* m, int pair, int g1, int g2) {
  m->pair_geom1[pair] = g1;
  m->pair_geom2[pair] = g2;
  if (m->geom_type[g1] > m->geom_type[g2]) std::swap(g1, g2);
  mjtNum* friction = m->pair_friction + 5 * pair;
  mjtNum* solref = m->pair_solref + mjNREF * pair;
  mjtNum* solimp = m->pair_solimp + mjNIMP * pair;
  m->pair_margin[pair] = mju_max(m->geom_margin[g1], m->geom_margin[g2]);
  m->pair_gap[pair] = mju_max(m->geom_gap[g1], m->geom_gap[g2]);
  if (m->geom_priority[g1] != m->geom_priority[g2]) {
    const int gp = m->geom_priority[g1] > m->geom_priority[g2] ? g1 : g2;
    m->pair_dim[pair] = m->geom_condim[gp];
    for (int i = 0; i < 3; ++i) friction[2 * i] = m->geom_friction[3 * gp + i];
    mju_copy(solref, m->geom_solref + mjNREF * gp, mjNREF);
    mju_copy(solimp, m->geom_solimp + mjNIMP * gp, mjNIMP);
  } else {
    m->pair_dim[pair] = std::max(m->geom_condim[g1], m->geom_condim[g2]);
    for (int i = 0; i < 3; ++i) {
      friction[2 * i] = mju_max(m->geom_friction[3 * g1 + i], m->geom_friction[3 * g2 + i]);
    }
    const mjtNum solmix1 = m->geom_solmix[g1];
    const mjtNum solmix2 = m->geom_solmix[g2];
    mjtNum mix;
    if (solmix1 >= mjMINVAL && solmix2 >= mjMINVAL) {
      mix = solmix1 / (solmix1 + solmix2);
    } else if (solmix1 < mjMINVAL && solmix2 < mjMINVAL) {
      mix = 0.5;
    } else if (solmix1 < mjMINVAL) {
      mix = 0.0;
    } else {
      mix = 1.0;
    }
    if (m->geom_solref[mjNREF * g1] > 0 && m->geom_solref[mjNREF * g2] > 0) {
      for (int i = 0; i < mjNREF; ++i) {
        solref[i] = mix * m->geom_solref[mjNREF * g1 + i] +
                    (1 - mix) * m->geom_solref[mjNREF * g2 + i];
      }
    } else {
      for (int i = 0; i < mjNREF; ++i) {
        solref[i] = mju_min(m->geom_solref[mjNREF * g1 + i], m->geom_solref[mjNREF * g2 + i]);
      }
    }
    mju_scl(solimp, m->geom_solimp + mjNIMP * g1, mix, mjNIMP);
    mju_addToScl(solimp, m->geom_solimp + mjNIMP * g2, 1 - mix, mjNIMP);
  }
  friction[1] = friction[0];
  friction[3] = friction[4];
}

// The local model's world: the <size> of the full model, `slots` free geom
// slots on the world body and `pairs` placeholder contact pairs (rewritten
// at every refresh, see ContactPairs).
std::string SlotWorldXml(const mjModel& full, int slots, int pairs) {
  std::ostringstream xml;
  xml << "<mujoco model=\"mjslam_local_physics\">\n  <size njmax=\"" << full.njmax
      << "\" nconmax=\"" << full.nconmax << "\" nstack=\"" << full.nstack << "\" nuserdata=\""
      << full.nuserdata << "\"/>\n  <worldbody>\n";
  for (int slot = 0; slot < slots; ++slot) {
    xml << "    <geom name=\"mjslam_slot_" << slot
        << "\" type=\"sphere\" size=\"0.001\" contype=\"0\" conaffinity=\"0\" group=\"4\" "
           "rgba=\"0 0 0 0\"/>\n";
  }
  xml << "  </worldbody>\n";
  if (pairs > 0) {
    xml << "  <contact>\n";
    for (int pair = 0; pair < pairs; ++pair) {
      xml << "    <pair geom1=\"mjslam_slot_0\" geom2=\"mjslam_slot_" << std::min(1, slots - 1)
          << "\"/>\n";
    }
    xml << "  </contact>\n";
  }
  xml << "</mujoco>\n";
  return xml.str();
}

}  // namespace

std::string LocalPhysics::Unsupported(const mjModel& full, const RobotIndices& full_ids) {
  if (full.npair > 0) return "the model has explicit contact pairs (<pair>)";
  if (full.nexclude > 0) return "the model has contact exclusions (<exclude>)";
  for (int geom = 0; geom < full.ngeom; ++geom) {
    if (IsRobotGeom(full, full_ids, geom) || !Collides(full, geom)) continue;
    if (!IsStatic(full, geom) || full.geom_bodyid[geom] != 0) {
      return "geom " + GeomLabel(full, geom) + " collides and is not on the world body";
    }
    if (full.geom_type[geom] == mjGEOM_MESH || full.geom_type[geom] == mjGEOM_HFIELD) {
      return "geom " + GeomLabel(full, geom) + " is a colliding mesh or height field";
    }
  }
  return "";
}

LocalPhysics::LocalPhysics(const Scene& scene, const mjModel& full, const RobotIndices& full_ids,
                           const LocalGeoms& geoms) {
  MJSLAM_CHECK(Unsupported(full, full_ids).empty());
  for (int geom = 0; geom < full.ngeom; ++geom) {
    if (full.geom_type[geom] == mjGEOM_PLANE && IsStatic(full, geom) && Collides(full, geom)) {
      planes_.push_back(geom);
    }
  }
  const int slots = static_cast<int>(planes_.size()) + geoms.MaxContactCandidates();
  int robot_colliding = 0;
  for (int geom = 0; geom < full.ngeom; ++geom) {
    if (IsRobotGeom(full, full_ids, geom) && Collides(full, geom)) ++robot_colliding;
  }
  // Enough pairs for every slot with every colliding robot geom, and for
  // every two colliding robot geoms (the placeholders name slots: none
  // without slots, and then MuJoCo finds the pairs itself).
  const int pairs =
      slots > 0 ? slots * robot_colliding + robot_colliding * (robot_colliding - 1) / 2 : 0;
  model_ = LoadRobotWithWorldXml(scene.robot_model_path(), SlotWorldXml(full, slots, pairs),
                                 "the local physics model of " + scene.Description());
  ids_ = FindRobotIndices(*model_, "robot model '" + scene.robot_model_path() + "'");
  MJSLAM_CHECK(model_->npair == pairs);
  model_->opt = full.opt;
  model_->stat = full.stat;
  const std::string difference = FirstRobotDifference(full, full_ids, *model_, ids_);
  if (!difference.empty()) {
    problem_ = "the robot compiles differently alone than with the world (" + difference +
               "): the world's <compiler> or <default> settings reach it";
    return;
  }
  first_local_robot_geom_ = FindRobotRows(*model_, ids_).geom;
  MJSLAM_CHECK(first_local_robot_geom_ == slots);
  robot_geom_offset_ = FindRobotRows(full, full_ids).geom - first_local_robot_geom_;
  slot_geom_.assign(slots, -1);
  for (int slot = 0; slot < slots; ++slot) FreeSlot(model_.get(), slot);
  pair_capacity_ = pairs;
  ListRobotPairs();
  UpdatePairs();
  data_ = MakeData(*model_, "starting the local physics model");
}

void LocalPhysics::ListRobotPairs() {
  const mjModel& m = *model_;
  // MuJoCo's broadphase would not skip a pair the explicit list collides:
  // its boxes hold each geom's bounding sphere (rbound and margin), so it
  // keeps every pair whose spheres meet; a geom without a bounding sphere
  // (rbound 0) has no such guarantee, nor does a contact filter callback or
  // a model that does not find its pairs itself.
  lists_pairs_ =
      m.opt.collision != mjCOL_PAIR && mjcb_contactfilter == nullptr && pair_capacity_ > 0;
  robot_geoms_.assign(m.nbody, {});
  for (int body = 1; body < m.nbody; ++body) {
    for (int geom = m.body_geomadr[body]; geom < m.body_geomadr[body] + m.body_geomnum[body];
         ++geom) {
      if (!Collides(m, geom)) continue;
      robot_geoms_[body].push_back(geom);
      if (m.geom_rbound[geom] <= 0) lists_pairs_ = false;
    }
  }
  // Robot with robot, in the broadphase's order (body pairs by id, then
  // the first body's geoms, then the second's).
  robot_pairs_.clear();
  for (int body1 = 1; body1 < m.nbody; ++body1) {
    for (int body2 = body1 + 1; body2 < m.nbody; ++body2) {
      for (int geom1 : robot_geoms_[body1]) {
        for (int geom2 : robot_geoms_[body2]) {
          if (!Filtered(m, geom1, geom2)) robot_pairs_.emplace_back(geom1, geom2);
        }
      }
    }
  }
  if (lists_pairs_) model_->opt.collision = mjCOL_PAIR;
}

void LocalPhysics::UpdatePairs() {
  if (!lists_pairs_) {
    model_->npair = 0;
    return;
  }
  // The order of MuJoCo's own search: the world body with each robot body
  // (by id), the world's geoms (the slots) before the robot body's; then the
  // robot's body pairs.
  mjModel* m = model_.get();
  int pair = 0;
  for (int body = 1; body < m->nbody; ++body) {
    for (int slot = 0; slot < static_cast<int>(slot_geom_.size()); ++slot) {
      if (slot_geom_[slot] < 0) continue;
      for (int geom : robot_geoms_[body]) {
        if (Filtered(*m, slot, geom)) continue;
        MJSLAM_CHECK(pair < pair_capacity_);
        SetPairAsFound(m, pair++, slot, geom);
      }
    }
  }
  for (const auto& [geom1, geom2] : robot_pairs_) {
    MJSLAM_CHECK(pair < pair_capacity_);
    SetPairAsFound(m, pair++, geom1, geom2);
  }
  m->npair = pair;
}

void LocalPhysics::Refresh(const mjModel& full, const LocalGeoms& geoms, const mjtNum* p_root,
                           bool force) {
  if (!refresh_.Due(p_root, geoms.contact_slack_m(), force)) return;
  // The planes and the walls near the root, in the full model's order.
  candidates_ = planes_;
  geoms.ForEachContactCandidate(Eigen::Vector2d(p_root[0], p_root[1]),
                                [&](int geom) { candidates_.push_back(geom); });
  std::sort(candidates_.begin(), candidates_.end());
  MJSLAM_CHECK(candidates_.size() <= slot_geom_.size());
  bool changed = false;
  for (std::size_t slot = 0; slot < slot_geom_.size(); ++slot) {
    const int geom = slot < candidates_.size() ? candidates_[slot] : -1;
    if (slot_geom_[slot] == geom) continue;
    if (geom >= 0) {
      CopyGeom(full, geom, model_.get(), static_cast<int>(slot));
    } else {
      FreeSlot(model_.get(), static_cast<int>(slot));
    }
    slot_geom_[slot] = geom;
    changed = true;
  }
  if (changed) UpdatePairs();
}

int LocalPhysics::FullGeom(int local_geom) const {
  if (local_geom < first_local_robot_geom_) return slot_geom_[local_geom];
  return local_geom + robot_geom_offset_;
}

int LocalPhysics::LocalGeom(int full_geom) const {
  if (full_geom >= first_local_robot_geom_ + robot_geom_offset_) {
    return full_geom - robot_geom_offset_;
  }
  const auto slot = std::find(slot_geom_.begin(), slot_geom_.end(), full_geom);
  return slot == slot_geom_.end() ? -1 : static_cast<int>(slot - slot_geom_.begin());
}

void CarryState(const mjModel& from_m, const mjData& from, const RobotIndices& from_ids,
                const mjModel& to_m, mjData* to, const RobotIndices& to_ids,
                const std::function<int(int)>& to_geom) {
  MJSLAM_CHECK(from_m.nq == to_m.nq && from_m.nv == to_m.nv && from_m.na == to_m.na &&
               from_m.nu == to_m.nu);
  std::copy_n(from.qpos, from_m.nq, to->qpos);
  std::copy_n(from.qvel, from_m.nv, to->qvel);
  std::copy_n(from.act, from_m.na, to->act);
  std::copy_n(from.ctrl, from_m.nu, to->ctrl);
  std::copy_n(from.qacc_warmstart, from_m.nv, to->qacc_warmstart);
  std::copy_n(from.qfrc_applied, from_m.nv, to->qfrc_applied);
  to->time = from.time;
  const RobotRows f = FindRobotRows(from_m, from_ids);
  const RobotRows t = FindRobotRows(to_m, to_ids);
  const auto rows = [](const mjtNum* source, int first_source, mjtNum* target, int first_target,
                       int count, int columns) {
    std::copy_n(source + first_source * columns, count * columns, target + first_target * columns);
  };
  rows(from.xpos, f.body, to->xpos, t.body, from_m.nbody - f.body, 3);
  rows(from.xquat, f.body, to->xquat, t.body, from_m.nbody - f.body, 4);
  rows(from.xmat, f.body, to->xmat, t.body, from_m.nbody - f.body, 9);
  rows(from.geom_xpos, f.geom, to->geom_xpos, t.geom, from_m.ngeom - f.geom, 3);
  rows(from.geom_xmat, f.geom, to->geom_xmat, t.geom, from_m.ngeom - f.geom, 9);
  rows(from.site_xpos, f.site, to->site_xpos, t.site, from_m.nsite - f.site, 3);
  rows(from.site_xmat, f.site, to->site_xmat, t.site, from_m.nsite - f.site, 9);
  to->ncon = from.ncon;
  for (int i = 0; i < from.ncon; ++i) {
    to->contact[i] = from.contact[i];
    to->contact[i].geom1 = to_geom(from.contact[i].geom1);
    to->contact[i].geom2 = to_geom(from.contact[i].geom2);
    MJSLAM_CHECK(to->contact[i].geom1 >= 0 && to->contact[i].geom2 >= 0);
  }
}

}  // namespace mjslam::sim::internal
