#pragma once

// Internal to sim/ and renders/ (it includes MuJoCo; tests/layering_test.cc
// keeps it out of every other folder): the loaded MuJoCo model behind a
// sim::Scene, for the code that puts physics (sim::Simulator) or drawing
// (renders::SceneRenderer) on top of it. Public headers expose common/ types
// only.

#include <array>
#include <cmath>
#include <memory>
#include <string>

#include <mujoco/mujoco.h>

#include "common/pose2.h"
#include "sim/scene.h"

namespace mjslam::sim::internal {

/// Frees an mjModel (unique_ptr deleter).
struct ModelDeleter {
  void operator()(mjModel* model) const { mj_deleteModel(model); }
};
/// Frees an mjData (unique_ptr deleter).
struct DataDeleter {
  void operator()(mjData* data) const { mj_deleteData(data); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

/// A deep copy of `model` (to change its options or colours without touching
/// the scene's). Throws SimError("<what>: MuJoCo error: ...") if MuJoCo fails.
ModelPtr CopyModel(const mjModel& model, const char* what);

/// Fresh data for `model` (mj_makeData), at the model's reference
/// configuration. Throws SimError as CopyModel.
DataPtr MakeData(const mjModel& model, const char* what);

/// Indices into the composed model of what the simulator drives and reads,
/// found by the scene's checks (models/README.md names them). Wheel arrays
/// are {left, right}.
struct RobotIndices {
  /// The robot's root body (the one with the free joint) and that joint's
  /// addresses in qpos and qvel.
  int root_body = -1;
  int root_qposadr = -1;
  int root_dofadr = -1;
  std::array<int, 2> wheel_qposadr{-1, -1};
  std::array<int, 2> wheel_dofadr{-1, -1};
  std::array<int, 2> wheel_actuator{-1, -1};
  std::array<int, 2> wheel_body{-1, -1};
  int laser_site = -1;
};

/// Geom group reserved for the robot (worlds use 0-4), masked out of the laser.
inline constexpr int kRobotGeomGroup = 5;

/// True when `geom` belongs to the robot (its body's root is the robot's).
inline bool IsRobotGeom(const mjModel& model, const RobotIndices& robot, int geom) {
  return model.body_rootid[model.geom_bodyid[geom]] == robot.root_body;
}

/// Yaw of a frame from its row-major rotation matrix (its x axis projected
/// on the floor plane).
inline double YawOf(const mjtNum* xmat) { return std::atan2(xmat[3], xmat[0]); }

/// Planar pose (x, y, yaw) of a site in the kinematics of `data`.
inline Pose2 SitePose(const mjData& data, int site) {
  const mjtNum* p = data.site_xpos + 3 * site;
  return Pose2(p[0], p[1], YawOf(data.site_xmat + 9 * site));
}

/// The robot model at `robot_model_path` composed with a world given as MJCF
/// text (included first, as Scene includes a world file), compiled. The
/// world text is a virtual file beside the robot model, so it must not
/// include files. Throws SimError("cannot load <description>: ...").
ModelPtr LoadRobotWithWorldXml(const std::string& robot_model_path, const std::string& world_xml,
                               const std::string& description);

/// The robot's indices in a composed model, found as Scene finds them
/// (throws SimError naming `robot_context` if a required name is missing).
RobotIndices FindRobotIndices(const mjModel& model, const std::string& robot_context);

/// "'name'" of a geom, or "#id" when it has no name (for messages).
std::string GeomLabel(const mjModel& model, int geom);

/// The model and indices behind a Scene (the only way to reach them).
class SceneAccess {
 public:
  /// The scene's compiled model, as loaded (never modified: copy it to
  /// change options).
  static const mjModel& Model(const Scene& scene);
  static const RobotIndices& Robot(const Scene& scene);
};

}  // namespace mjslam::sim::internal
