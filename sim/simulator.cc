#include "sim/simulator.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <sstream>

#include <mujoco/mujoco.h>

#include "common/angles.h"
#include "common/check.h"
#include "sim/diff_drive.h"

namespace mjslam::sim {
namespace {

namespace fs = std::filesystem;

// The wrapper's file name in MuJoCo's virtual file system. It is looked up
// there by base name, so a world file must not have this name.
constexpr char kSceneFileName[] = "mjslam_composed_scene.xml";
// Names the simulator relies on (models/README.md, worlds/README.md).
constexpr char kLaserSite[] = "laser";
constexpr char kStartSite[] = "start";
constexpr char kTourPrefix[] = "tour_";
constexpr char kLeftWheelJoint[] = "p3dx_left_wheel_joint";
constexpr char kRightWheelJoint[] = "p3dx_right_wheel_joint";
constexpr char kLeftWheelMotor[] = "p3dx_left_wheel_motor";
constexpr char kRightWheelMotor[] = "p3dx_right_wheel_motor";
// Geom group reserved for the robot, masked out of the laser.
constexpr int kRobotGeomGroup = 5;
// How far the robot may rise or sink, and tilt, before it counts as having
// left the floor.
constexpr double kMaxHeightChange_m = 0.05;
constexpr double kMaxTilt_rad = DegToRad(15.0);

void ThrowMujocoError(const char* message) {
  throw SimError(std::string("MuJoCo error: ") + message);
}

void ThrowMujocoWarning(const char* message) {
  throw SimError(std::string("MuJoCo warning: ") + message);
}

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

std::string Name(const mjModel* m, int type, int id) {
  const char* name = mj_id2name(m, type, id);
  return name != nullptr ? std::string(name) : std::string();
}

std::string GeomLabel(const mjModel* m, int geom) {
  const std::string name = Name(m, mjOBJ_GEOM, geom);
  return name.empty() ? "#" + std::to_string(geom) : "'" + name + "'";
}

// Yaw of a frame from its row-major rotation matrix (x axis projected on the
// floor plane).
double YawOf(const mjtNum* xmat) { return std::atan2(xmat[3], xmat[0]); }

std::string PoseText(const Pose2& pose) {
  std::ostringstream text;
  text << "(x " << pose.x << " m, y " << pose.y << " m, yaw " << RadToDeg(pose.theta)
       << " deg)";
  return text.str();
}

// Owns MuJoCo's virtual file system (about 2 MB, so on the heap).
struct VfsDeleter {
  void operator()(mjVFS* vfs) const {
    mj_deleteVFS(vfs);
    delete vfs;
  }
};

}  // namespace

void InstallMujocoErrorHandlers() {
  if (mju_user_error == nullptr) mju_user_error = &ThrowMujocoError;
  if (mju_user_warning == nullptr) mju_user_warning = &ThrowMujocoWarning;
}

std::string MujocoVersion() { return mj_versionString(); }

struct Simulator::Impl {
  SimParams sim;
  RobotParams robot;
  std::string world_path;
  std::string robot_path;
  std::string scene_xml;
  mjModel* m = nullptr;
  mjData* d = nullptr;

  int root_body = -1;
  int root_qposadr = -1;
  int root_dofadr = -1;
  std::array<int, 2> wheel_qposadr{-1, -1};
  std::array<int, 2> wheel_dofadr{-1, -1};
  std::array<int, 2> wheel_actuator{-1, -1};
  std::array<int, 2> wheel_body{-1, -1};
  int laser_site = -1;
  int start_site = -1;
  std::vector<int> tour_sites;

  Pose2 X_RS;
  Twist2 command;
  // Wheel-speed controller: set points (rad/s) and integrated errors (rad).
  std::array<double, 2> speed_setpoint_radps{0.0, 0.0};
  std::array<double, 2> speed_error_integral_rad{0.0, 0.0};
  double requested_time_s = 0.0;
  long long steps = 0;
  double rest_height_m = 0.0;

  ~Impl() {
    if (d != nullptr) mj_deleteData(d);
    if (m != nullptr) mj_deleteModel(m);
  }

  bool IsRobotGeom(int geom) const { return m->body_rootid[m->geom_bodyid[geom]] == root_body; }

  std::string FileContext() const {
    return "world '" + world_path + "' with robot '" + robot_path + "'";
  }

  void Load(const std::string& world_in, const std::string& robot_in);
  void CheckModel();
  void Place(const Pose2& X_WR);
  void Settle();
  void Step();
  void CheckOnFloor() const;

  Pose2 X_WA() const {
    const mjtNum* p = d->xpos + 3 * root_body;
    return Pose2(p[0], p[1], YawOf(d->xmat + 9 * root_body));
  }
  Pose2 X_WR() const { return X_WA() * Pose2(robot.control_point_offset_m, 0.0, 0.0); }
  Pose2 SitePose(int site) const {
    const mjtNum* p = d->site_xpos + 3 * site;
    return Pose2(p[0], p[1], YawOf(d->site_xmat + 9 * site));
  }
  int CountRobotWorldContacts() const;
  std::string FirstRobotWorldContact() const;
};

void Simulator::Impl::Load(const std::string& world_in, const std::string& robot_in) {
  // Both files must exist; MuJoCo's own message for a missing include is cryptic.
  const fs::path world = fs::absolute(world_in).lexically_normal();
  const fs::path robot_file = fs::absolute(robot_in).lexically_normal();
  world_path = world.string();
  robot_path = robot_file.string();
  if (!fs::is_regular_file(world)) throw SimError("world file not found: '" + world_in + "'");
  if (!fs::is_regular_file(robot_file)) {
    throw SimError("robot model file not found: '" + robot_in + "'");
  }
  if (world.filename() == kSceneFileName) {
    throw SimError("world file '" + world_path + "' must not be named " + kSceneFileName);
  }

  // Each file alone first: through an include, MuJoCo's messages lose the
  // file name and line number.
  using KindAndPath = std::pair<std::string, std::string>;
  for (const auto& [kind, path] :
       {KindAndPath{"world", world_path}, KindAndPath{"robot model", robot_path}}) {
    char error[1024] = "";
    mjModel* alone = mj_loadXML(path.c_str(), nullptr, error, sizeof(error));
    if (alone == nullptr) {
      throw SimError("cannot load " + kind + " '" + path + "': " + std::string(error));
    }
    mj_deleteModel(alone);
  }

  // The wrapper lives (virtually) in the world's directory and includes both
  // files relative to it, so the world's own includes and assets resolve as
  // when it is loaded alone (MuJoCo 2.2 prefixes every include with the main
  // file's directory, absolute paths too).
  const fs::path world_dir = world.parent_path();
  const std::string robot_relative = fs::relative(robot_file, world_dir).generic_string();
  if (robot_relative.empty()) {
    throw SimError("cannot reach robot model '" + robot_path + "' from '" +
                   world_dir.string() + "'");
  }
  scene_xml = "<mujoco model=\"mjslam_scene\">\n  <include file=\"" +
              XmlEscape(world.filename().string()) + "\"/>\n  <include file=\"" +
              XmlEscape(robot_relative) + "\"/>\n</mujoco>\n";

  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);
  mj_defaultVFS(vfs.get());
  MJSLAM_CHECK(mj_makeEmptyFileVFS(vfs.get(), kSceneFileName,
                                   static_cast<int>(scene_xml.size())) == 0);
  const int file = mj_findFileVFS(vfs.get(), kSceneFileName);
  MJSLAM_CHECK(file >= 0);
  std::memcpy(vfs->filedata[file], scene_xml.data(), scene_xml.size());

  char error[1024] = "";
  const std::string scene_path = (world_dir / kSceneFileName).string();
  m = mj_loadXML(scene_path.c_str(), vfs.get(), error, sizeof(error));
  if (m == nullptr) {
    throw SimError("cannot load " + FileContext() + ": " + std::string(error));
  }
  d = mj_makeData(m);
  if (d == nullptr) throw SimError("cannot allocate MuJoCo data for " + FileContext());
}

void Simulator::Impl::CheckModel() {
  const std::string robot_context = "robot model '" + robot_path + "'";
  const std::string world_context = "world '" + world_path + "'";

  // The robot: its laser site, the root body with the free joint, the wheels.
  laser_site = mj_name2id(m, mjOBJ_SITE, kLaserSite);
  if (laser_site < 0) throw SimError(robot_context + " has no site 'laser'");
  root_body = m->body_rootid[m->site_bodyid[laser_site]];
  if (root_body <= 0 || m->body_jntnum[root_body] != 1 ||
      m->jnt_type[m->body_jntadr[root_body]] != mjJNT_FREE) {
    throw SimError(robot_context + ": the site 'laser' must be on a body with a free joint");
  }
  root_qposadr = m->jnt_qposadr[m->body_jntadr[root_body]];
  root_dofadr = m->jnt_dofadr[m->body_jntadr[root_body]];
  const std::array<const char*, 2> joint_names{kLeftWheelJoint, kRightWheelJoint};
  const std::array<const char*, 2> motor_names{kLeftWheelMotor, kRightWheelMotor};
  for (int i = 0; i < 2; ++i) {
    const int joint = mj_name2id(m, mjOBJ_JOINT, joint_names[i]);
    if (joint < 0 || m->jnt_type[joint] != mjJNT_HINGE) {
      throw SimError(robot_context + " has no hinge joint '" + joint_names[i] + "'");
    }
    wheel_qposadr[i] = m->jnt_qposadr[joint];
    wheel_dofadr[i] = m->jnt_dofadr[joint];
    wheel_body[i] = m->jnt_bodyid[joint];
    wheel_actuator[i] = mj_name2id(m, mjOBJ_ACTUATOR, motor_names[i]);
    if (wheel_actuator[i] < 0 || m->actuator_trnid[2 * wheel_actuator[i]] != joint) {
      throw SimError(robot_context + " has no actuator '" + motor_names[i] + "' on joint '" +
                     joint_names[i] + "'");
    }
  }

  // Geom groups: 5 is the robot's, and only the robot's.
  for (int geom = 0; geom < m->ngeom; ++geom) {
    const bool in_robot_group = m->geom_group[geom] == kRobotGeomGroup;
    if (IsRobotGeom(geom) && !in_robot_group) {
      throw SimError(robot_context + ": geom " + GeomLabel(m, geom) + " must be in group 5");
    }
    if (!IsRobotGeom(geom) && in_robot_group) {
      throw SimError(world_context + " uses geom group 5 (geom " + GeomLabel(m, geom) +
                     "), which is reserved for the robot; use groups 0-4");
    }
  }

  // The world is static: every joint and actuator belongs to the robot.
  for (int joint = 0; joint < m->njnt; ++joint) {
    if (m->body_rootid[m->jnt_bodyid[joint]] != root_body) {
      throw SimError(world_context + " has a joint ('" + Name(m, mjOBJ_JOINT, joint) +
                     "'): worlds must contain static geoms only");
    }
  }
  if (m->nu != 2) {
    throw SimError(world_context + " adds actuators: worlds must contain static geoms only");
  }

  // Sites of the world: start, and tour_0 ... tour_{n-1} without gaps.
  start_site = mj_name2id(m, mjOBJ_SITE, kStartSite);
  if (start_site < 0) throw SimError(world_context + " has no site named 'start'");
  std::map<int, int> tour;  // index -> site id
  const std::size_t prefix_length = std::strlen(kTourPrefix);
  for (int site = 0; site < m->nsite; ++site) {
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
  int expected = 0;
  for (const auto& [index, site] : tour) {
    if (index != expected) {
      throw SimError(world_context + ": tour sites must be numbered tour_0, tour_1, ... "
                     "without gaps (tour_" + std::to_string(expected) + " is missing)");
    }
    tour_sites.push_back(site);
    ++expected;
  }

  // Wheel radius and axle track of the model must match RobotParams.
  mj_kinematics(m, d);
  std::array<double, 2> radius{};
  for (int i = 0; i < 2; ++i) {
    int contact_geom = -1;
    for (int geom = 0; geom < m->ngeom; ++geom) {
      if (m->geom_bodyid[geom] != wheel_body[i]) continue;
      if (m->geom_contype[geom] == 0 && m->geom_conaffinity[geom] == 0) continue;
      if (contact_geom >= 0 || (m->geom_type[geom] != mjGEOM_SPHERE &&
                                m->geom_type[geom] != mjGEOM_CYLINDER)) {
        throw SimError(robot_context + ": each wheel needs exactly one colliding geom, "
                       "a sphere or a cylinder");
      }
      contact_geom = geom;
    }
    if (contact_geom < 0) throw SimError(robot_context + ": a wheel has no colliding geom");
    radius[i] = m->geom_size[3 * contact_geom];
  }
  const mjtNum* p_left = d->xpos + 3 * wheel_body[0];
  const mjtNum* p_right = d->xpos + 3 * wheel_body[1];
  const double track = std::hypot(p_left[0] - p_right[0], p_left[1] - p_right[1]);
  const auto require_match = [&](const char* key, double params_value, double model_value) {
    if (std::abs(params_value - model_value) > 1e-3) {
      std::ostringstream message;
      message << "RobotParams " << key << " = " << params_value << " disagrees with "
              << robot_context << " (" << model_value << ") by more than 1 mm";
      throw SimError(message.str());
    }
  };
  require_match("wheel_radius_m (left)", robot.wheel_radius_m, radius[0]);
  require_match("wheel_radius_m (right)", robot.wheel_radius_m, radius[1]);
  require_match("axle_track_m", robot.axle_track_m, track);

  // The wheel-speed loop's gain must be stable with explicit integration:
  // kp dt / I < 1, I the wheel's inertia about its axle plus armature.
  for (int i = 0; i < 2; ++i) {
    const double inertia =
        m->dof_armature[wheel_dofadr[i]] + m->body_inertia[3 * wheel_body[i] + 1];
    if (sim.wheel_speed_kp_nms_per_rad * sim.timestep_s / inertia >= 1.0) {
      std::ostringstream message;
      message << "SimParams wheel_speed_kp_nms_per_rad = " << sim.wheel_speed_kp_nms_per_rad
              << " with timestep_s = " << sim.timestep_s << " is unstable for the wheels of "
              << robot_context << " (inertia " << inertia << " kg m^2): need kp dt / I < 1";
      throw SimError(message.str());
    }
  }
}

int Simulator::Impl::CountRobotWorldContacts() const {
  int count = 0;
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& contact = d->contact[i];
    const bool robot1 = IsRobotGeom(contact.geom1);
    const bool robot2 = IsRobotGeom(contact.geom2);
    if (robot1 == robot2) continue;
    const int world_geom = robot1 ? contact.geom2 : contact.geom1;
    if (m->geom_type[world_geom] == mjGEOM_PLANE) continue;
    ++count;
  }
  return count;
}

std::string Simulator::Impl::FirstRobotWorldContact() const {
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& contact = d->contact[i];
    const bool robot1 = IsRobotGeom(contact.geom1);
    const bool robot2 = IsRobotGeom(contact.geom2);
    if (robot1 == robot2) continue;
    const int world_geom = robot1 ? contact.geom2 : contact.geom1;
    const int robot_geom = robot1 ? contact.geom1 : contact.geom2;
    if (m->geom_type[world_geom] == mjGEOM_PLANE) continue;
    return "robot geom " + GeomLabel(m, robot_geom) + " touches world geom " +
           GeomLabel(m, world_geom);
  }
  return "";
}

void Simulator::Impl::Place(const Pose2& X_WR_start) {
  // The free joint keeps the model's height (axle at wheel radius) and gets
  // the start pose's x, y and yaw; the robot starts level and at rest.
  mj_resetData(m, d);
  const Pose2 X_WA = X_WR_start * Pose2(-robot.control_point_offset_m, 0.0, 0.0);
  mjtNum* qpos = d->qpos + root_qposadr;
  qpos[0] = X_WA.x;
  qpos[1] = X_WA.y;
  qpos[3] = std::cos(0.5 * X_WA.theta);
  qpos[4] = 0.0;
  qpos[5] = 0.0;
  qpos[6] = std::sin(0.5 * X_WA.theta);
  mj_forward(m, d);

  // X_RS from the level, just placed robot: constant from now on.
  X_RS = X_WR().Inverse() * SitePose(laser_site);

  if (CountRobotWorldContacts() > 0) {
    throw SimError("the start pose " + PoseText(X_WR_start) + " in " + FileContext() +
                   " is in collision: " + FirstRobotWorldContact());
  }
}

void Simulator::Impl::Settle() {
  const Pose2 X_WA_placed = X_WA();
  const double placed_height = d->xpos[3 * root_body + 2];
  const long long settle_steps = std::llround(sim.settle_time_s / sim.timestep_s);
  speed_setpoint_radps = {0.0, 0.0};
  speed_error_integral_rad = {0.0, 0.0};
  for (long long i = 0; i < settle_steps; ++i) Step();
  const Pose2 X_WA_settled = X_WA();
  rest_height_m = d->xpos[3 * root_body + 2];
  const double moved = std::hypot(X_WA_settled.x - X_WA_placed.x, X_WA_settled.y - X_WA_placed.y);
  const double turned = std::abs(WrapAngle(X_WA_settled.theta - X_WA_placed.theta));
  const double sunk = std::abs(rest_height_m - placed_height);
  if (moved > 0.005 || turned > 0.005 || sunk > 0.01) {
    std::ostringstream message;
    message << "the robot did not come to rest at the start of " << FileContext()
            << " (moved " << moved << " m, turned " << RadToDeg(turned) << " deg, height change "
            << sunk << " m after " << sim.settle_time_s
            << " s): does the world have a floor plane at z = 0?";
    throw SimError(message.str());
  }
  d->time = 0.0;
}

void Simulator::Impl::Step() {
  // Wheel-speed PI control, torque clamped to the actuator range; the error
  // integrates only while the torque is not saturated (or it helps unwind).
  for (int i = 0; i < 2; ++i) {
    const int actuator = wheel_actuator[i];
    const double error = speed_setpoint_radps[i] - d->qvel[wheel_dofadr[i]];
    const double integral = speed_error_integral_rad[i] + error * m->opt.timestep;
    const double torque = sim.wheel_speed_kp_nms_per_rad * error +
                          sim.wheel_speed_ki_nm_per_rad * integral;
    double applied = torque;
    if (m->actuator_ctrllimited[actuator]) {
      applied = std::clamp(torque, m->actuator_ctrlrange[2 * actuator],
                           m->actuator_ctrlrange[2 * actuator + 1]);
    }
    if (applied == torque || error * torque < 0.0) speed_error_integral_rad[i] = integral;
    d->ctrl[actuator] = applied;
  }
  mj_step(m, d);
  // The warning handler throws on the first occurrence; this catches warnings
  // when another handler was installed after ours.
  for (int warning = 0; warning < mjNWARNING; ++warning) {
    if (d->warning[warning].number > 0) {
      std::ostringstream message;
      message << "MuJoCo warning at t = " << d->time << " s in " << FileContext() << ": "
              << mju_warningText(warning, d->warning[warning].lastinfo);
      throw SimError(message.str());
    }
  }
}

void Simulator::Impl::CheckOnFloor() const {
  const double height = d->xpos[3 * root_body + 2];
  const double up_z = d->xmat[9 * root_body + 8];  // z component of the body's z axis
  if (std::abs(height - rest_height_m) > kMaxHeightChange_m || up_z < std::cos(kMaxTilt_rad)) {
    std::ostringstream message;
    message << "the robot left the floor at t = " << d->time << " s in " << FileContext()
            << " (axle height " << height << " m, rest " << rest_height_m << " m, tilt "
            << RadToDeg(std::acos(std::clamp(up_z, -1.0, 1.0))) << " deg)";
    const std::string contact = FirstRobotWorldContact();
    if (!contact.empty()) message << "; " << contact;
    throw SimError(message.str());
  }
}

Simulator::Simulator(const std::string& world_path, const std::string& robot_model_path,
                     const SimParams& sim, const RobotParams& robot,
                     std::optional<Pose2> X_WR_start)
    : impl_(std::make_unique<Impl>()) {
  sim.ValidateOrThrow();
  robot.ValidateOrThrow();
  InstallMujocoErrorHandlers();
  impl_->sim = sim;
  impl_->robot = robot;
  impl_->Load(world_path, robot_model_path);
  impl_->m->opt.timestep = sim.timestep_s;
  impl_->CheckModel();
  // The start site's pose, at the model's reference configuration.
  mj_kinematics(impl_->m, impl_->d);
  const Pose2 start = impl_->SitePose(impl_->start_site);
  impl_->Place(X_WR_start.value_or(start));
  impl_->Settle();
}

Simulator::~Simulator() = default;
Simulator::Simulator(Simulator&&) noexcept = default;
Simulator& Simulator::operator=(Simulator&&) noexcept = default;

Twist2 Simulator::SetCommand(const Twist2& command) {
  const Twist2 applied = SaturateTwist(command, impl_->robot);
  const WheelSpeeds wheels = WheelSpeedsFromTwist(applied, impl_->robot);
  impl_->speed_setpoint_radps = {wheels.left_radps, wheels.right_radps};
  impl_->command = applied;
  return applied;
}

Twist2 Simulator::command() const { return impl_->command; }

void Simulator::Advance(double duration_s) {
  if (!(duration_s >= 0.0) || !std::isfinite(duration_s)) {
    throw SimError("Advance: duration must be finite and >= 0 (got " +
                   std::to_string(duration_s) + ")");
  }
  impl_->requested_time_s += duration_s;
  const long long target_steps = std::llround(impl_->requested_time_s / impl_->sim.timestep_s);
  while (impl_->steps < target_steps) {
    impl_->Step();
    ++impl_->steps;
  }
  impl_->CheckOnFloor();
}

double Simulator::time_s() const { return impl_->d->time; }
double Simulator::timestep_s() const { return impl_->m->opt.timestep; }

Pose2 Simulator::X_WR() const { return impl_->X_WR(); }
Pose2 Simulator::X_RS() const { return impl_->X_RS; }
Pose2 Simulator::X_WS() const { return impl_->X_WR() * impl_->X_RS; }

Twist2 Simulator::TrueTwist() const {
  const mjtNum* qvel = impl_->d->qvel + impl_->root_dofadr;
  const double yaw = impl_->X_WA().theta;
  // Free joint: linear velocity of the body origin (the axle centre) in W,
  // then angular velocity in the body frame (its z is ~vertical).
  Twist2 twist;
  twist.v_mps = qvel[0] * std::cos(yaw) + qvel[1] * std::sin(yaw);
  twist.w_radps = qvel[5];
  return twist;
}

std::array<double, 2> Simulator::WheelAngles() const {
  return {impl_->d->qpos[impl_->wheel_qposadr[0]], impl_->d->qpos[impl_->wheel_qposadr[1]]};
}

std::array<double, 2> Simulator::WheelVelocities() const {
  return {impl_->d->qvel[impl_->wheel_dofadr[0]], impl_->d->qvel[impl_->wheel_dofadr[1]]};
}

LaserScan Simulator::CastLaser(const LaserParams& laser,
                               const std::vector<double>& beam_angle_offsets_rad) const {
  laser.ValidateOrThrow();
  if (!beam_angle_offsets_rad.empty() &&
      static_cast<int>(beam_angle_offsets_rad.size()) != laser.num_beams) {
    throw SimError("CastLaser: " + std::to_string(beam_angle_offsets_rad.size()) +
                   " beam angle offsets for " + std::to_string(laser.num_beams) + " beams");
  }
  const mjModel* m = impl_->m;
  const mjData* d = impl_->d;

  LaserScan scan;
  scan.t_s = d->time;
  scan.angle_min_rad = laser.AngleMinRad();
  scan.angle_increment_rad = laser.AngleIncrementRad();
  scan.max_range_m = laser.max_range_m;
  scan.ranges_m.assign(laser.num_beams, laser.max_range_m);
  scan.has_return.assign(laser.num_beams, 0);

  // Every geom group but the robot's; static (world body) geoms included.
  mjtByte geom_groups[mjNGROUP];
  for (int group = 0; group < mjNGROUP; ++group) geom_groups[group] = group != kRobotGeomGroup;
  const Pose2 X_WS = this->X_WS();
  const mjtNum origin[3] = {X_WS.x, X_WS.y, d->site_xpos[3 * impl_->laser_site + 2]};
  for (int i = 0; i < laser.num_beams; ++i) {
    const double offset = beam_angle_offsets_rad.empty() ? 0.0 : beam_angle_offsets_rad[i];
    const double bearing_W = X_WS.theta + scan.BeamAngle(i) + offset;
    const mjtNum direction[3] = {std::cos(bearing_W), std::sin(bearing_W), 0.0};
    int geom = -1;
    const mjtNum distance = mj_ray(m, d, origin, direction, geom_groups, 1, -1, &geom);
    if (distance >= 0.0 && distance < laser.max_range_m) {
      scan.ranges_m[i] = distance;
      scan.has_return[i] = 1;
    }
  }
  return scan;
}

std::vector<Eigen::Vector2d> Simulator::TourWaypoints() const {
  std::vector<Eigen::Vector2d> waypoints;
  for (const int site : impl_->tour_sites) {
    const mjtNum* p = impl_->d->site_xpos + 3 * site;
    waypoints.emplace_back(p[0], p[1]);
  }
  return waypoints;
}

Pose2 Simulator::StartPose() const { return impl_->SitePose(impl_->start_site); }

int Simulator::CountRobotWorldContacts() const { return impl_->CountRobotWorldContacts(); }

std::vector<ObstacleFootprint> Simulator::Obstacles() const {
  const mjModel* m = impl_->m;
  const mjData* d = impl_->d;
  std::vector<ObstacleFootprint> obstacles;
  for (int geom = 0; geom < m->ngeom; ++geom) {
    const int type = m->geom_type[geom];
    if (impl_->IsRobotGeom(geom) || type == mjGEOM_PLANE || type == mjGEOM_HFIELD) continue;
    const mjtNum* p = d->geom_xpos + 3 * geom;
    const mjtNum* R = d->geom_xmat + 9 * geom;
    const mjtNum* size = m->geom_size + 3 * geom;
    const bool upright = std::abs(R[8]) > 1.0 - 1e-9;
    ObstacleFootprint obstacle;
    obstacle.name = Name(m, mjOBJ_GEOM, geom);
    obstacle.X_WO = Pose2(p[0], p[1], upright ? YawOf(R) : 0.0);
    double half_height = m->geom_rbound[geom];
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
      obstacle.radius_m = m->geom_rbound[geom];
      obstacle.exact = false;
    }
    obstacle.z_min_m = p[2] - half_height;
    obstacle.z_max_m = p[2] + half_height;
    obstacles.push_back(obstacle);
  }
  return obstacles;
}

const RobotParams& Simulator::robot() const { return impl_->robot; }
const std::string& Simulator::world_path() const { return impl_->world_path; }
const std::string& Simulator::robot_model_path() const { return impl_->robot_path; }

std::vector<double> Simulator::QPos() const {
  return std::vector<double>(impl_->d->qpos, impl_->d->qpos + impl_->m->nq);
}

const std::string& Simulator::SceneXml() const { return impl_->scene_xml; }

}  // namespace mjslam::sim
