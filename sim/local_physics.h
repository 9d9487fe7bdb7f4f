#pragma once

// Internal to sim/ (it includes MuJoCo; tests/layering_test.cc keeps it
// there): the small physics model the simulator steps in place of the full
// scene (sim/README.md, "The local physics model").

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <mujoco/mujoco.h>

#include "sim/local_geoms.h"
#include "sim/scene.h"
#include "sim/scene_model.h"

namespace mjslam::sim::internal {

/// A MuJoCo model of the robot and a pool of world geom slots, stepped
/// instead of the full scene: each slot takes, at a refresh, every field of
/// one static world geom of the full model that can touch the robot before
/// the next refresh (the planes always; the walls LocalGeoms lists within
/// its contact radius), in the full model's geom order; the other slots do
/// not collide. MuJoCo then finds the same contacts in the same order as in
/// the full model and the physics is the same, bit for bit, while every
/// step's cost (kinematics, the pair loop) depends on the slots only, not on
/// the size of the world. MuJoCo's broadphase is replaced by the list of the
/// geom pairs it would find (explicit pairs, rewritten at each refresh).
/// The robot part of the model is compiled from the same robot file and
/// checked against the full model's (every floating-point array of its
/// bodies, geoms, sites, joints, dofs and actuators); options and statistics
/// are copied from the full model (but opt.collision, see lists_pairs_).
class LocalPhysics {
 public:
  /// Why the full model `full` cannot be replaced by a local model (empty
  /// when it can): only static world-body geoms that are primitives or
  /// planes may collide, and the model has no explicit <pair> or <exclude>.
  static std::string Unsupported(const mjModel& full, const RobotIndices& full_ids);

  /// Builds the local model for `scene`, whose physics copy is `full` (with
  /// its options), with MaxContactCandidates() of `geoms` plus the planes as
  /// slots, and fresh data. Unsupported(full, full_ids) must be empty.
  /// When the robot compiles differently than in the full model (e.g. the
  /// world's <compiler> reaches it), problem() says so and the model must
  /// not be used. Throws SimError if MuJoCo fails.
  LocalPhysics(const Scene& scene, const mjModel& full, const RobotIndices& full_ids,
               const LocalGeoms& geoms);

  /// Why this model must not replace the full one (empty: it can).
  const std::string& problem() const { return problem_; }

  mjModel* model() { return model_.get(); }
  mjData* data() { return data_.get(); }
  const mjModel& model() const { return *model_; }
  const mjData& data() const { return *data_; }
  /// The robot's indices in the local model.
  const RobotIndices& ids() const { return ids_; }

  /// Fills the slots with the geoms of `full` that `geoms` lists near the
  /// robot's root position `p_root` (x, y: the position the next mj_step
  /// collides at), when the root has moved more than the contact slack since
  /// the last refresh, or when `force`.
  void Refresh(const mjModel& full, const LocalGeoms& geoms, const mjtNum* p_root,
               bool force = false);

  /// The full model's id of geom `local_geom` of the local model (a slot's
  /// present occupant, or a robot geom), for messages; -1 for a free slot.
  int FullGeom(int local_geom) const;
  /// The local id of geom `full_geom` of the full model (a robot geom, or a
  /// world geom now in a slot); -1 if it is in no slot.
  int LocalGeom(int full_geom) const;

 private:
  std::string problem_;
  ModelPtr model_;
  DataPtr data_;
  RobotIndices ids_;
  // The full model's colliding planes (always in a slot), ids.
  std::vector<int> planes_;
  // The full geom in each slot (-1: free); slots are geoms 0..n-1.
  std::vector<int> slot_geom_;
  // Full robot geom id minus local robot geom id.
  int robot_geom_offset_ = 0;
  int first_local_robot_geom_ = 0;
  ContactRefresh refresh_;
  std::vector<int> candidates_;
  // The geom pairs MuJoCo's broadphase would find, listed as the model's
  // explicit pairs (opt.collision = mjCOL_PAIR): the same contacts in the
  // same order without the broadphase (sim/README.md, "The local physics
  // model"). False: MuJoCo finds them itself.
  bool lists_pairs_ = false;
  int pair_capacity_ = 0;
  // Each robot body's colliding geoms (index: local body id).
  std::vector<std::vector<int>> robot_geoms_;
  // The robot's geom pairs that MuJoCo's contact filter lets through.
  std::vector<std::pair<int, int>> robot_pairs_;

  void ListRobotPairs();
  // Rewrites the explicit pairs for the present slots (npair: the pairs in
  // use; the model holds pair_capacity_).
  void UpdatePairs();
};

/// Copies the state of `from` into `to` (models of the same robot: equal
/// nq, nv, na, nu, and the robot's bodies, geoms and sites the last rows of
/// each): qpos, qvel, act, ctrl, qacc_warmstart, qfrc_applied, time, and
/// what the simulator reads between steps as the last mj_step left it (the
/// robot's body, geom and site poses, and the contacts, their geoms renamed
/// by `to_geom`, which maps a geom of `from_m` to its id in `to_m`). The
/// next mj_step in `to` recomputes everything else from that state.
void CarryState(const mjModel& from_m, const mjData& from, const RobotIndices& from_ids,
                const mjModel& to_m, mjData* to, const RobotIndices& to_ids,
                const std::function<int(int)>& to_geom);

}  // namespace mjslam::sim::internal
