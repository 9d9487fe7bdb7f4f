#include "sim/scene.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <sstream>
#include <utility>

#include <mujoco/mujoco.h>

#include "common/check.h"
#include "sim/scene_model.h"

namespace mjslam::sim {

struct Scene::Impl {
  std::string world_path;
  std::string robot_path;
  internal::ModelPtr model;
  internal::RobotIndices robot;
  Pose2 start;
  std::vector<Eigen::Vector2d> tour;
  std::vector<ObstacleFootprint> obstacles;
  std::array<double, 2> wheel_radius_m{0.0, 0.0};
  double axle_track_m = 0.0;
};

namespace {

namespace fs = std::filesystem;
using internal::RobotIndices;

// The wrapper's file name in MuJoCo's virtual file system. It is looked up
// there by base name, so a world file must not have this name.
constexpr char kSceneFileName[] = "mjslam_composed_scene.xml";
// Names the scene relies on (models/README.md, worlds/README.md).
constexpr char kLaserSite[] = "laser";
constexpr char kStartSite[] = "start";
constexpr char kTourPrefix[] = "tour_";
constexpr char kLeftWheelJoint[] = "p3dx_left_wheel_joint";
constexpr char kRightWheelJoint[] = "p3dx_right_wheel_joint";
constexpr char kLeftWheelMotor[] = "p3dx_left_wheel_motor";
constexpr char kRightWheelMotor[] = "p3dx_right_wheel_motor";

std::string XmlEscape(const std::string& text) {
  std::string escaped;
  for (const char c : text) {
    switch (c) {
      case '&': escaped += "&amp;"; break;
      case '<': escaped += "&lt;"; break;
      case '>': escaped += "&gt;"; break;
      case '"': escaped += "&quot;"; break;
      case '\'': escaped += "&apos;"; break;
      default: escaped += c;
    }
  }
  return escaped;
}

std::string Name(const mjModel& m, int type, int id) {
  const char* name = mj_id2name(&m, type, id);
  return name != nullptr ? std::string(name) : std::string();
}

// Owns MuJoCo's virtual file system (about 2 MB, so on the heap).
struct VfsDeleter {
  void operator()(mjVFS* vfs) const {
    mj_deleteVFS(vfs);
    delete vfs;
  }
};

std::string DescribeFiles(const std::string& world_path, const std::string& robot_path) {
  return "world '" + world_path + "' with robot '" + robot_path + "'";
}

// Context strings for the messages of the checks.
struct Contexts {
  std::string world;
  std::string robot;
};

// Each file alone: through an include, MuJoCo's messages lose the file name
// and line number. mj_loadXML is not trapped (its parser is C++, so an
// error could not be longjmp'd over): it reports through its error buffer,
// and MuJoCo 2.2's compiler traps its own engine errors there.
internal::ModelPtr LoadAlone(const std::string& kind, const std::string& path) {
  char error[1024] = "";
  internal::ModelPtr alone(mj_loadXML(path.c_str(), nullptr, error, sizeof(error)));
  if (alone == nullptr) {
    throw SimError("cannot load " + kind + " '" + path + "': " + std::string(error));
  }
  return alone;
}

// A world must not set <option> (worlds/README.md): the robot model's options
// govern the composed scene. Loaded alone, the world has MuJoCo's default
// options unless it sets some (mjOption is doubles then ints: no padding).
void CheckWorldSetsNoOption(const mjModel& world_alone, const std::string& world_context) {
  mjOption defaults;
  mj_defaultOption(&defaults);
  static_assert(sizeof(mjOption) == 25 * sizeof(mjtNum) + 10 * sizeof(int));
  if (std::memcmp(&world_alone.opt, &defaults, sizeof(mjOption)) != 0) {
    throw SimError(world_context + " sets <option>: worlds must not (the robot model's options "
                   "govern the scene and the simulator sets the timestep)");
  }
}

// The wrapper MJCF that includes the world and the robot. It lives
// (virtually) in the world's directory and includes both files relative to
// it, so the world's own includes and assets resolve as when it is loaded
// alone (MuJoCo 2.2 prefixes every include with the main file's directory,
// absolute paths too).
std::string CompositionXml(const fs::path& world, const fs::path& robot_file) {
  const fs::path world_dir = world.parent_path();
  const std::string robot_relative = fs::relative(robot_file, world_dir).generic_string();
  if (robot_relative.empty()) {
    throw SimError("cannot reach robot model '" + robot_file.string() + "' from '" +
                   world_dir.string() + "'");
  }
  return "<mujoco model=\"mjslam_scene\">\n  <include file=\"" +
         XmlEscape(world.filename().string()) + "\"/>\n  <include file=\"" +
         XmlEscape(robot_relative) + "\"/>\n</mujoco>\n";
}

// Loads the composed scene through a virtual file named kSceneFileName in
// the directory of `beside` (a file path), with `extra_files` (name, text)
// in the virtual file system too.
internal::ModelPtr LoadComposed(
    const fs::path& beside, const std::string& scene_xml, const std::string& description,
    const std::vector<std::pair<std::string, std::string>>& extra_files = {}) {
  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);
  mj_defaultVFS(vfs.get());
  const auto add_file = [&](const std::string& name, const std::string& text) {
    MJSLAM_CHECK(mj_makeEmptyFileVFS(vfs.get(), name.c_str(), static_cast<int>(text.size())) == 0);
    const int file = mj_findFileVFS(vfs.get(), name.c_str());
    MJSLAM_CHECK(file >= 0);
    std::memcpy(vfs->filedata[file], text.data(), text.size());
  };
  add_file(kSceneFileName, scene_xml);
  for (const auto& [name, text] : extra_files) add_file(name, text);

  char error[1024] = "";
  const std::string scene_path = (beside.parent_path() / kSceneFileName).string();
  internal::ModelPtr model(mj_loadXML(scene_path.c_str(), vfs.get(), error, sizeof(error)));
  if (model == nullptr) throw SimError("cannot load " + description + ": " + std::string(error));
  return model;
}

// The robot: its laser site, the root body with the free joint, the wheels
// and their motors.
RobotIndices FindRobot(const mjModel& m, const std::string& robot_context) {
  RobotIndices robot;
  robot.laser_site = mj_name2id(&m, mjOBJ_SITE, kLaserSite);
  if (robot.laser_site < 0) throw SimError(robot_context + " has no site 'laser'");
  robot.root_body = m.body_rootid[m.site_bodyid[robot.laser_site]];
  const int root = robot.root_body;
  if (root <= 0 || m.body_jntnum[root] != 1 || m.jnt_type[m.body_jntadr[root]] != mjJNT_FREE) {
    throw SimError(robot_context + ": the site 'laser' must be on a body with a free joint");
  }
  robot.root_qposadr = m.jnt_qposadr[m.body_jntadr[root]];
  robot.root_dofadr = m.jnt_dofadr[m.body_jntadr[root]];
  const std::array<const char*, 2> joint_names{kLeftWheelJoint, kRightWheelJoint};
  const std::array<const char*, 2> motor_names{kLeftWheelMotor, kRightWheelMotor};
  for (int i = 0; i < 2; ++i) {
    const int joint = mj_name2id(&m, mjOBJ_JOINT, joint_names[i]);
    if (joint < 0 || m.jnt_type[joint] != mjJNT_HINGE) {
      throw SimError(robot_context + " has no hinge joint '" + joint_names[i] + "'");
    }
    robot.wheel_qposadr[i] = m.jnt_qposadr[joint];
    robot.wheel_dofadr[i] = m.jnt_dofadr[joint];
    robot.wheel_body[i] = m.jnt_bodyid[joint];
    robot.wheel_actuator[i] = mj_name2id(&m, mjOBJ_ACTUATOR, motor_names[i]);
    if (robot.wheel_actuator[i] < 0 || m.actuator_trnid[2 * robot.wheel_actuator[i]] != joint) {
      throw SimError(robot_context + " has no actuator '" + motor_names[i] + "' on joint '" +
                     joint_names[i] + "'");
    }
  }
  return robot;
}

// Geom groups: 5 is the robot's, and only the robot's.
void CheckGeomGroups(const mjModel& m, const RobotIndices& robot, const Contexts& context) {
  for (int geom = 0; geom < m.ngeom; ++geom) {
    const bool in_robot_group = m.geom_group[geom] == internal::kRobotGeomGroup;
    const bool robot_geom = internal::IsRobotGeom(m, robot, geom);
    if (robot_geom && !in_robot_group) {
      throw SimError(context.robot + ": geom " + internal::GeomLabel(m, geom) +
                     " must be in group 5");
    }
    if (!robot_geom && in_robot_group) {
      throw SimError(context.world + " uses geom group 5 (geom " + internal::GeomLabel(m, geom) +
                     "), which is reserved for the robot; use groups 0-4");
    }
  }
}

// The world is static: every joint and actuator belongs to the robot.
void CheckWorldIsStatic(const mjModel& m, const RobotIndices& robot,
                        const std::string& world_context) {
  for (int joint = 0; joint < m.njnt; ++joint) {
    if (m.body_rootid[m.jnt_bodyid[joint]] != robot.root_body) {
      throw SimError(world_context + " has a joint ('" + Name(m, mjOBJ_JOINT, joint) +
                     "'): worlds must contain static geoms only");
    }
  }
  if (m.nu != 2) {
    throw SimError(world_context + " adds actuators: worlds must contain static geoms only");
  }
}

// The site `start`; throws if the world has none.
int FindStartSite(const mjModel& m, const std::string& world_context) {
  const int start_site = mj_name2id(&m, mjOBJ_SITE, kStartSite);
  if (start_site < 0) throw SimError(world_context + " has no site named 'start'");
  return start_site;
}

// The sites tour_0 ... tour_{n-1} in order; throws on a gap or a name that
// starts with tour_ but is not tour_<number>.
std::vector<int> FindTourSites(const mjModel& m, const std::string& world_context) {
  std::map<int, int> tour;  // index -> site id
  const std::size_t prefix_length = std::strlen(kTourPrefix);
  for (int site = 0; site < m.nsite; ++site) {
    const std::string name = Name(m, mjOBJ_SITE, site);
    if (name.compare(0, prefix_length, kTourPrefix) != 0) continue;
    const std::string digits = name.substr(prefix_length);
    const bool numeric = !digits.empty() && digits.size() <= 6 &&
                         std::all_of(digits.begin(), digits.end(),
                                     [](char c) { return c >= '0' && c <= '9'; });
    if (!numeric) {
      throw SimError(world_context + ": site '" + name + "' is not of the form tour_<number>");
    }
    tour[std::stoi(digits)] = site;
  }
  std::vector<int> sites;
  int expected = 0;
  for (const auto& [index, site] : tour) {
    if (index != expected) {
      throw SimError(world_context + ": tour sites must be numbered tour_0, tour_1, ... "
                     "without gaps (tour_" + std::to_string(expected) + " is missing)");
    }
    sites.push_back(site);
    ++expected;
  }
  return sites;
}

// The radius of each wheel's single colliding geom (a sphere or a cylinder).
std::array<double, 2> WheelRadii(const mjModel& m, const RobotIndices& robot,
                                 const std::string& robot_context) {
  std::array<double, 2> radius{};
  for (int i = 0; i < 2; ++i) {
    int contact_geom = -1;
    for (int geom = 0; geom < m.ngeom; ++geom) {
      if (m.geom_bodyid[geom] != robot.wheel_body[i]) continue;
      if (m.geom_contype[geom] == 0 && m.geom_conaffinity[geom] == 0) continue;
      if (contact_geom >= 0 || (m.geom_type[geom] != mjGEOM_SPHERE &&
                                m.geom_type[geom] != mjGEOM_CYLINDER)) {
        throw SimError(robot_context + ": each wheel needs exactly one colliding geom, "
                       "a sphere or a cylinder");
      }
      contact_geom = geom;
    }
    if (contact_geom < 0) throw SimError(robot_context + ": a wheel has no colliding geom");
    radius[i] = m.geom_size[3 * contact_geom];
  }
  return radius;
}

// Footprints of the obstacle geoms at the kinematics in `d`.
std::vector<ObstacleFootprint> ReadObstacles(const mjModel& m, const mjData& d,
                                             const RobotIndices& robot) {
  std::vector<ObstacleFootprint> obstacles;
  for (int geom = 0; geom < m.ngeom; ++geom) {
    const int type = m.geom_type[geom];
    if (internal::IsRobotGeom(m, robot, geom) || type == mjGEOM_PLANE || type == mjGEOM_HFIELD) {
      continue;
    }
    const mjtNum* p = d.geom_xpos + 3 * geom;
    const mjtNum* R = d.geom_xmat + 9 * geom;
    const mjtNum* size = m.geom_size + 3 * geom;
    const bool upright = std::abs(R[8]) > 1.0 - 1e-9;
    ObstacleFootprint obstacle;
    obstacle.name = Name(m, mjOBJ_GEOM, geom);
    obstacle.X_WO = Pose2(p[0], p[1], upright ? internal::YawOf(R) : 0.0);
    double half_height = m.geom_rbound[geom];
    if (type == mjGEOM_BOX && upright) {
      obstacle.shape = ObstacleFootprint::Shape::kRectangle;
      obstacle.half_extents_m = Eigen::Vector2d(size[0], size[1]);
      half_height = size[2];
    } else if ((type == mjGEOM_CYLINDER || type == mjGEOM_CAPSULE) && upright) {
      obstacle.shape = ObstacleFootprint::Shape::kCircle;
      obstacle.radius_m = size[0];
      half_height = type == mjGEOM_CYLINDER ? size[1] : size[1] + size[0];
    } else if (type == mjGEOM_SPHERE) {
      obstacle.shape = ObstacleFootprint::Shape::kCircle;
      obstacle.radius_m = size[0];
      half_height = size[0];
    } else {
      obstacle.shape = ObstacleFootprint::Shape::kCircle;
      obstacle.radius_m = m.geom_rbound[geom];
      obstacle.exact = false;
    }
    obstacle.z_min_m = p[2] - half_height;
    obstacle.z_max_m = p[2] + half_height;
    obstacles.push_back(obstacle);
  }
  return obstacles;
}

}  // namespace

std::shared_ptr<const Scene::Impl> Scene::Load(const std::string& world_in,
                                               const std::string& robot_in) {
  InstallMujocoErrorHandlers();
  // Both files must exist; MuJoCo's own message for a missing include is cryptic.
  const fs::path world = fs::absolute(world_in).lexically_normal();
  const fs::path robot_file = fs::absolute(robot_in).lexically_normal();
  auto scene = std::make_shared<Impl>();
  scene->world_path = world.string();
  scene->robot_path = robot_file.string();
  if (!fs::is_regular_file(world)) throw SimError("world file not found: '" + world_in + "'");
  if (!fs::is_regular_file(robot_file)) {
    throw SimError("robot model file not found: '" + robot_in + "'");
  }
  if (world.filename() == kSceneFileName) {
    throw SimError("world file '" + scene->world_path + "' must not be named " + kSceneFileName);
  }
  const internal::ModelPtr world_alone = LoadAlone("world", scene->world_path);
  LoadAlone("robot model", scene->robot_path);
  scene->model = LoadComposed(world, CompositionXml(world, robot_file),
                              DescribeFiles(scene->world_path, scene->robot_path));

  // The rules of the robot model and of the world.
  const mjModel& m = *scene->model;
  const Contexts context{"world '" + scene->world_path + "'",
                         "robot model '" + scene->robot_path + "'"};
  scene->robot = FindRobot(m, context.robot);
  CheckGeomGroups(m, scene->robot, context);
  CheckWorldIsStatic(m, scene->robot, context.world);
  CheckWorldSetsNoOption(*world_alone, context.world);
  const int start_site = FindStartSite(m, context.world);
  const std::vector<int> tour_sites = FindTourSites(m, context.world);
  scene->wheel_radius_m = WheelRadii(m, scene->robot, context.robot);

  // What the scene reports, at the reference configuration.
  const internal::DataPtr data = internal::MakeData(m, "reading the scene");
  mjData* d = data.get();
  CallMujoco("reading the scene", [&] { mj_kinematics(&m, d); });
  scene->start = internal::SitePose(*d, start_site);
  for (const int site : tour_sites) {
    const mjtNum* p = d->site_xpos + 3 * site;
    scene->tour.emplace_back(p[0], p[1]);
  }
  scene->obstacles = ReadObstacles(m, *d, scene->robot);
  const mjtNum* p_left = d->xpos + 3 * scene->robot.wheel_body[0];
  const mjtNum* p_right = d->xpos + 3 * scene->robot.wheel_body[1];
  scene->axle_track_m = std::hypot(p_left[0] - p_right[0], p_left[1] - p_right[1]);
  return scene;
}

Scene::Scene(const std::string& world_path, const std::string& robot_model_path)
    : impl_(Load(world_path, robot_model_path)) {}

const Pose2& Scene::StartPose() const { return impl_->start; }
const std::vector<Eigen::Vector2d>& Scene::TourWaypoints() const { return impl_->tour; }
const std::vector<ObstacleFootprint>& Scene::Obstacles() const { return impl_->obstacles; }
const std::array<double, 2>& Scene::WheelRadiiM() const { return impl_->wheel_radius_m; }
double Scene::AxleTrackM() const { return impl_->axle_track_m; }
const std::string& Scene::world_path() const { return impl_->world_path; }
const std::string& Scene::robot_model_path() const { return impl_->robot_path; }

std::string Scene::Description() const {
  return DescribeFiles(impl_->world_path, impl_->robot_path);
}

void CheckWorldExtent(const Scene& scene, double max_extent_m) {
  CheckWorldExtent(scene.world_path(), scene.StartPose().translation(), scene.Obstacles(),
                   max_extent_m);
}

void CheckWorldExtent(const std::string& world_path, const Eigen::Vector2d& start,
                      const std::vector<ObstacleFootprint>& obstacles, double max_extent_m) {
  Eigen::Vector2d lo = start, hi = start;
  // The obstacle that reaches farthest from the start along an axis, for the
  // message.
  const ObstacleFootprint* farthest = nullptr;
  double farthest_m = 0.0;
  for (const ObstacleFootprint& o : obstacles) {
    // The footprint's axis-aligned bounds: a rectangle's corners, a disc's box.
    Eigen::Vector2d o_lo = o.X_WO.translation(), o_hi = o_lo;
    if (o.shape == ObstacleFootprint::Shape::kRectangle) {
      for (const Eigen::Vector2d& corner : RectangleCorners(o)) {
        o_lo = o_lo.cwiseMin(corner);
        o_hi = o_hi.cwiseMax(corner);
      }
    } else {
      o_lo.array() -= o.radius_m;
      o_hi.array() += o.radius_m;
    }
    const double distance =
        std::max((o_hi - start).cwiseAbs().maxCoeff(), (o_lo - start).cwiseAbs().maxCoeff());
    if (!std::isfinite(distance) || distance > farthest_m) {
      farthest = &o;
      farthest_m = distance;
      if (!std::isfinite(distance)) break;
    }
    lo = lo.cwiseMin(o_lo);
    hi = hi.cwiseMax(o_hi);
  }
  const double extent = (hi - lo).maxCoeff();
  if (std::isfinite(farthest_m) && extent <= max_extent_m) return;
  std::ostringstream message;
  message << "world '" << world_path << "' spans " << extent
          << " m, more than sim.max_world_extent_m = " << max_extent_m << " m";
  if (farthest != nullptr) {
    message << " (geom " << (farthest->name.empty() ? "without a name" : "'" + farthest->name + "'")
            << " at (" << farthest->X_WO.x << ", " << farthest->X_WO.y << ") reaches "
            << farthest_m << " m from the start)";
  }
  throw SimError(message.str());
}

namespace internal {

ModelPtr CopyModel(const mjModel& model, const char* what) {
  mjModel* copy = nullptr;
  CallMujoco(what, [&] { copy = mj_copyModel(nullptr, &model); });
  if (copy == nullptr) throw SimError(std::string(what) + ": cannot copy the MuJoCo model");
  return ModelPtr(copy);
}

DataPtr MakeData(const mjModel& model, const char* what) {
  mjData* data = nullptr;
  CallMujoco(what, [&] { data = mj_makeData(&model); });
  if (data == nullptr) throw SimError(std::string(what) + ": cannot allocate MuJoCo data");
  return DataPtr(data);
}

ModelPtr LoadRobotWithWorldXml(const std::string& robot_model_path, const std::string& world_xml,
                               const std::string& description) {
  const fs::path robot_file = fs::absolute(robot_model_path).lexically_normal();
  const std::string world_name = "mjslam_generated_world.xml";
  const std::string scene_xml = "<mujoco model=\"mjslam_scene\">\n  <include file=\"" +
                                world_name + "\"/>\n  <include file=\"" +
                                XmlEscape(robot_file.filename().string()) + "\"/>\n</mujoco>\n";
  return LoadComposed(robot_file, scene_xml, description, {{world_name, world_xml}});
}

RobotIndices FindRobotIndices(const mjModel& model, const std::string& robot_context) {
  return FindRobot(model, robot_context);
}

std::string GeomLabel(const mjModel& model, int geom) {
  const std::string name = Name(model, mjOBJ_GEOM, geom);
  return name.empty() ? "#" + std::to_string(geom) : "'" + name + "'";
}

const mjModel& SceneAccess::Model(const Scene& scene) { return *scene.impl_->model; }
const RobotIndices& SceneAccess::Robot(const Scene& scene) { return scene.impl_->robot; }

}  // namespace internal
}  // namespace mjslam::sim
