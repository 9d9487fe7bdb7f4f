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

// The local model's world: the <size> of the full model and `slots` free
// geom slots on the world body.
std::string SlotWorldXml(const mjModel& full, int slots) {
  std::ostringstream xml;
  xml << "<mujoco model=\"mjslam_local_physics\">\n  <size njmax=\"" << full.njmax
      << "\" nconmax=\"" << full.nconmax << "\" nstack=\"" << full.nstack << "\" nuserdata=\""
      << full.nuserdata << "\"/>\n  <worldbody>\n";
  for (int slot = 0; slot < slots; ++slot) {
    xml << "    <geom name=\"mjslam_slot_" << slot
        << "\" type=\"sphere\" size=\"0.001\" contype=\"0\" conaffinity=\"0\" group=\"4\" "
           "rgba=\"0 0 0 0\"/>\n";
  }
  xml << "  </worldbody>\n</mujoco>\n";
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
  model_ = LoadRobotWithWorldXml(scene.robot_model_path(), SlotWorldXml(full, slots),
                                 "the local physics model of " + scene.Description());
  ids_ = FindRobotIndices(*model_, "robot model '" + scene.robot_model_path() + "'");
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
  data_ = MakeData(*model_, "starting the local physics model");
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
  for (std::size_t slot = 0; slot < slot_geom_.size(); ++slot) {
    const int geom = slot < candidates_.size() ? candidates_[slot] : -1;
    if (slot_geom_[slot] == geom) continue;
    if (geom >= 0) {
      CopyGeom(full, geom, model_.get(), static_cast<int>(slot));
    } else {
      FreeSlot(model_.get(), static_cast<int>(slot));
    }
    slot_geom_[slot] = geom;
  }
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
