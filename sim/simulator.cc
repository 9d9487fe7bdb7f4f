#include "sim/simulator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include <mujoco/mujoco.h>

#include "common/angles.h"
#include "common/check.h"
#include "sim/diff_drive.h"
#include "sim/local_geoms.h"
#include "sim/local_physics.h"
#include "sim/scene_model.h"

namespace mjslam::sim {
namespace {

using internal::kRobotGeomGroup;

// How far the robot may rise or sink, and tilt, before it counts as having
// left the floor.
constexpr double kMaxHeightChange_m = 0.05;
constexpr double kMaxTilt_rad = DegToRad(15.0);

std::string PoseText(const Pose2& pose) {
  std::ostringstream text;
  text << "(x " << pose.x << " m, y " << pose.y << " m, yaw " << RadToDeg(pose.theta)
       << " deg)";
  return text.str();
}

// The wheel radii and axle track of RobotParams must match the model's to
// 1 mm.
void CheckRobotParamsMatch(const Scene& scene, const RobotParams& robot) {
  const std::string robot_context = "robot model '" + scene.robot_model_path() + "'";
  const auto require_match = [&](const char* key, double params_value, double model_value) {
    if (std::abs(params_value - model_value) > 1e-3) {
      std::ostringstream message;
      message << "RobotParams " << key << " = " << params_value << " disagrees with "
              << robot_context << " (" << model_value << ") by more than 1 mm";
      throw SimError(message.str());
    }
  };
  require_match("wheel_radius_m (left)", robot.wheel_radius_m, scene.WheelRadiiM()[0]);
  require_match("wheel_radius_m (right)", robot.wheel_radius_m, scene.WheelRadiiM()[1]);
  require_match("axle_track_m", robot.axle_track_m, scene.AxleTrackM());
}

// The wheel-speed loop's gain must be stable with explicit integration:
// kp dt / I < 1, I the wheel's inertia about its axle plus armature.
void CheckWheelGainIsStable(const Scene& scene, const SimParams& sim) {
  const mjModel& m = internal::SceneAccess::Model(scene);
  const internal::RobotIndices& ids = internal::SceneAccess::Robot(scene);
  for (int i = 0; i < 2; ++i) {
    const double inertia =
        m.dof_armature[ids.wheel_dofadr[i]] + m.body_inertia[3 * ids.wheel_body[i] + 1];
    if (sim.wheel_speed_kp_nms_per_rad * sim.timestep_s / inertia >= 1.0) {
      std::ostringstream message;
      message << "SimParams wheel_speed_kp_nms_per_rad = " << sim.wheel_speed_kp_nms_per_rad
              << " with timestep_s = " << sim.timestep_s << " is unstable for the wheels of "
              << "robot model '" << scene.robot_model_path() << "' (inertia " << inertia
              << " kg m^2): need kp dt / I < 1";
      throw SimError(message.str());
    }
  }
}

// The laser's geom groups for mj_ray: every group but the robot's.
void LaserGeomGroups(mjtByte groups[mjNGROUP]) {
  for (int group = 0; group < mjNGROUP; ++group) groups[group] = group != kRobotGeomGroup;
}

// Validates the params before loading the files (the order of the checks of
// the path constructor).
Scene ValidatedScene(const std::string& world_path, const std::string& robot_model_path,
                     const SimParams& sim, const RobotParams& robot) {
  sim.ValidateOrThrow();
  robot.ValidateOrThrow();
  return Scene(world_path, robot_model_path);
}

}  // namespace

struct Simulator::Impl {
  explicit Impl(Scene scene_in) : scene(std::move(scene_in)) {}

  Scene scene;
  SimParams sim;
  RobotParams robot;
  // The physics being stepped: the full model or the local one (m, d and
  // the robot's indices in it).
  internal::RobotIndices ids;
  mjModel* m = nullptr;
  mjData* d = nullptr;
  // The simulator's copy of the scene's model (its options carry the
  // timestep) and its data: the full scene (the laser's static poses; the
  // physics while local_geoms_on is false or no local model is possible).
  internal::ModelPtr model;
  internal::DataPtr data;
  internal::RobotIndices full_ids;

  Pose2 X_RS;
  Twist2 command;
  // The twist the set points are made from: the command, or with the
  // drive's acceleration limits the command ramped (from rest).
  Twist2 ramped;
  bool Ramps() const { return sim.command_accel_mps2 > 0.0 || sim.command_accel_radps2 > 0.0; }
  // The drive's disturbance: the set points are those of (v v, w w) of these.
  Twist2 drive_factors{1.0, 1.0};
  // Each wheel's disturbance: its set point times these (left, right).
  std::array<double, 2> wheel_factors{1.0, 1.0};
  // Wheel-speed controller: set points (rad/s) and integrated errors (rad).
  std::array<double, 2> speed_setpoint_radps{0.0, 0.0};
  std::array<double, 2> speed_error_integral_rad{0.0, 0.0};
  double requested_time_s = 0.0;
  long long steps = 0;
  double rest_height_m = 0.0;
  // The static world geoms in a grid (contacts near the robot, beams along
  // their cells); used while local_geoms_on.
  std::optional<internal::LocalGeoms> local_geoms;
  bool local_geoms_on = true;
  // The local physics model (sim/README.md, "The local physics model"),
  // when the world allows one; stepped while local_geoms_on.
  std::optional<internal::LocalPhysics> local_physics;
  // Why there is none ("" when there is).
  std::string local_model_problem;
  bool UsingLocalPhysics() const { return m != model.get(); }
  // Makes the local model (true) or the full one (false) the one stepped,
  // carrying the state over.
  void UseLocalPhysics(bool on);

  bool IsRobotGeom(int geom) const { return internal::IsRobotGeom(*m, ids, geom); }

  void Place(const Pose2& X_WR);
  void Settle();
  void Step();
  void CheckOnFloor() const;
  // The wheel-speed set points of the command, scaled by the drive's factors.
  void ApplySetPoints() {
    const Twist2& twist = Ramps() ? ramped : command;
    const Twist2 asked{twist.v_mps * drive_factors.v_mps, twist.w_radps * drive_factors.w_radps};
    const WheelSpeeds wheels = WheelSpeedsFromTwist(asked, robot);
    speed_setpoint_radps = {wheels.left_radps * wheel_factors[0],
                            wheels.right_radps * wheel_factors[1]};
  }

  Pose2 X_WA() const {
    const mjtNum* p = d->xpos + 3 * ids.root_body;
    return Pose2(p[0], p[1], internal::YawOf(d->xmat + 9 * ids.root_body));
  }
  Pose2 X_WR() const { return X_WA() * Pose2(robot.control_point_offset_m, 0.0, 0.0); }
  int CountRobotWorldContacts() const;
  std::string FirstRobotWorldContact() const;
};

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
    const auto label = [this](int geom) {
      return UsingLocalPhysics() ? internal::GeomLabel(*model, local_physics->FullGeom(geom))
                                 : internal::GeomLabel(*m, geom);
    };
    return "robot geom " + label(robot_geom) + " touches world geom " + label(world_geom);
  }
  return "";
}

void Simulator::Impl::Place(const Pose2& X_WR_start) {
  // The free joint keeps the model's height (axle at wheel radius) and gets
  // the start pose's x, y and yaw; the robot starts level and at rest.
  const Pose2 X_WA = X_WR_start * Pose2(-robot.control_point_offset_m, 0.0, 0.0);
  const std::string what = "placing the robot in " + scene.Description();
  CallMujoco(what.c_str(), [&] {
    mj_resetData(m, d);
    mjtNum* qpos = d->qpos + ids.root_qposadr;
    qpos[0] = X_WA.x;
    qpos[1] = X_WA.y;
    qpos[3] = std::cos(0.5 * X_WA.theta);
    qpos[4] = 0.0;
    qpos[5] = 0.0;
    qpos[6] = std::sin(0.5 * X_WA.theta);
    mj_forward(m, d);
  });

  // X_RS from the level, just placed robot: constant from now on.
  X_RS = X_WR().Inverse() * internal::SitePose(*d, ids.laser_site);

  if (CountRobotWorldContacts() > 0) {
    throw SimError("the start pose " + PoseText(X_WR_start) + " in " + scene.Description() +
                   " is in collision: " + FirstRobotWorldContact());
  }
}

void Simulator::Impl::Settle() {
  const Pose2 X_WA_placed = X_WA();
  const double placed_height = d->xpos[3 * ids.root_body + 2];
  const long long settle_steps = std::llround(sim.settle_time_s / sim.timestep_s);
  speed_setpoint_radps = {0.0, 0.0};
  speed_error_integral_rad = {0.0, 0.0};
  for (long long i = 0; i < settle_steps; ++i) Step();
  const Pose2 X_WA_settled = X_WA();
  rest_height_m = d->xpos[3 * ids.root_body + 2];
  const double moved = std::hypot(X_WA_settled.x - X_WA_placed.x, X_WA_settled.y - X_WA_placed.y);
  const double turned = std::abs(WrapAngle(X_WA_settled.theta - X_WA_placed.theta));
  const double sunk = std::abs(rest_height_m - placed_height);
  if (moved > 0.005 || turned > 0.005 || sunk > 0.01) {
    std::ostringstream message;
    message << "the robot did not come to rest at the start of " << scene.Description()
            << " (moved " << moved << " m, turned " << RadToDeg(turned) << " deg, height change "
            << sunk << " m after " << sim.settle_time_s
            << " s): does the world have a floor plane at z = 0?";
    throw SimError(message.str());
  }
  d->time = 0.0;
}

void Simulator::Impl::Step() {
  if (Ramps()) {
    auto toward = [this](double from, double to, double limit) {
      if (limit <= 0.0) return to;
      const double most = limit * m->opt.timestep;
      return from + std::clamp(to - from, -most, most);
    };
    ramped = Twist2{toward(ramped.v_mps, command.v_mps, sim.command_accel_mps2),
                    toward(ramped.w_radps, command.w_radps, sim.command_accel_radps2)};
    ApplySetPoints();
  }
  // Wheel-speed PI control, torque clamped to the actuator range; the error
  // integrates only while the torque is not saturated (or it helps unwind).
  for (int i = 0; i < 2; ++i) {
    const int actuator = ids.wheel_actuator[i];
    const double error = speed_setpoint_radps[i] - d->qvel[ids.wheel_dofadr[i]];
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
  // Only the world geoms within the robot's reach collide (same contacts).
  if (UsingLocalPhysics()) {
    local_physics->Refresh(*model, *local_geoms, d->qpos + ids.root_qposadr);
  } else if (local_geoms_on) {
    local_geoms->FilterContacts(m, d->qpos + ids.root_qposadr);
  }
  auto step = [this] { mj_step(m, d); };
  const std::string problem = TrapMujocoErrors(step);
  if (!problem.empty()) {
    std::ostringstream message;
    message << "at t = " << d->time << " s in " << scene.Description() << ": " << problem;
    throw SimError(message.str());
  }
  // The warning handler records the first occurrence of a warning; this
  // catches warnings when another handler was installed after ours.
  for (int warning = 0; warning < mjNWARNING; ++warning) {
    if (d->warning[warning].number > 0) {
      std::ostringstream message;
      message << "MuJoCo warning at t = " << d->time << " s in " << scene.Description() << ": "
              << mju_warningText(warning, d->warning[warning].lastinfo);
      throw SimError(message.str());
    }
  }
}

void Simulator::Impl::UseLocalPhysics(bool on) {
  if (on == UsingLocalPhysics()) return;
  mjModel* from_m = m;
  mjData* from_d = d;
  const internal::RobotIndices from_ids = ids;
  if (on) {
    local_physics->Refresh(*model, *local_geoms, d->qpos + ids.root_qposadr, /*force=*/true);
    m = local_physics->model();
    d = local_physics->data();
    ids = local_physics->ids();
  } else {
    m = model.get();
    d = data.get();
    ids = full_ids;
  }
  const internal::LocalPhysics& local = *local_physics;
  const auto to_geom = [on, &local](int geom) {
    return on ? local.LocalGeom(geom) : local.FullGeom(geom);
  };
  internal::CarryState(*from_m, *from_d, from_ids, *m, d, ids, to_geom);
}

void Simulator::Impl::CheckOnFloor() const {
  const double height = d->xpos[3 * ids.root_body + 2];
  const double up_z = d->xmat[9 * ids.root_body + 8];  // z component of the body's z axis
  if (std::abs(height - rest_height_m) > kMaxHeightChange_m || up_z < std::cos(kMaxTilt_rad)) {
    std::ostringstream message;
    message << "the robot left the floor at t = " << d->time << " s in " << scene.Description()
            << " (axle height " << height << " m, rest " << rest_height_m << " m, tilt "
            << RadToDeg(std::acos(std::clamp(up_z, -1.0, 1.0))) << " deg)";
    const std::string contact = FirstRobotWorldContact();
    if (!contact.empty()) message << "; " << contact;
    throw SimError(message.str());
  }
}

Simulator::Simulator(Scene scene, const SimParams& sim, const RobotParams& robot,
                     std::optional<Pose2> X_WR_start)
    : impl_(std::make_unique<Impl>(std::move(scene))) {
  sim.ValidateOrThrow();
  robot.ValidateOrThrow();
  Impl& r = *impl_;
  r.sim = sim;
  r.robot = robot;
  CheckWorldExtent(r.scene, sim.max_world_extent_m);
  CheckRobotParamsMatch(r.scene, robot);
  CheckWheelGainIsStable(r.scene, sim);

  // The physics: a copy of the scene's model with the timestep, fresh data.
  r.ids = internal::SceneAccess::Robot(r.scene);
  r.full_ids = r.ids;
  r.model = internal::CopyModel(internal::SceneAccess::Model(r.scene), "starting the physics");
  r.m = r.model.get();
  r.m->opt.timestep = sim.timestep_s;
  r.data = internal::MakeData(*r.m, "starting the physics");
  r.d = r.data.get();
  r.Place(X_WR_start.value_or(r.scene.StartPose()));
  mjtByte laser_groups[mjNGROUP];
  LaserGeomGroups(laser_groups);
  r.local_geoms.emplace(*r.m, *r.d, r.ids, laser_groups);
  r.local_model_problem = internal::LocalPhysics::Unsupported(*r.m, r.ids);
  if (r.local_model_problem.empty()) {
    r.local_physics.emplace(r.scene, *r.m, r.ids, *r.local_geoms);
    r.local_model_problem = r.local_physics->problem();
    if (r.local_model_problem.empty()) {
      r.UseLocalPhysics(true);
    } else {
      r.local_physics.reset();
    }
  }
  r.Settle();
}

Simulator::Simulator(const std::string& world_path, const std::string& robot_model_path,
                     const SimParams& sim, const RobotParams& robot,
                     std::optional<Pose2> X_WR_start)
    : Simulator(ValidatedScene(world_path, robot_model_path, sim, robot), sim, robot,
                X_WR_start) {}

Simulator::~Simulator() = default;
Simulator::Simulator(Simulator&&) noexcept = default;
Simulator& Simulator::operator=(Simulator&&) noexcept = default;

Twist2 Simulator::SetCommand(const Twist2& command) {
  const Twist2 applied = SaturateTwist(command, impl_->robot);
  impl_->command = applied;
  impl_->ApplySetPoints();
  return applied;
}

void Simulator::SetDriveFactors(double v_factor, double w_factor) {
  MJSLAM_CHECK(std::isfinite(v_factor) && std::isfinite(w_factor));
  impl_->drive_factors = Twist2{v_factor, w_factor};
  impl_->ApplySetPoints();
}

void Simulator::SetWheelFactors(double left_factor, double right_factor) {
  MJSLAM_CHECK(std::isfinite(left_factor) && std::isfinite(right_factor));
  impl_->wheel_factors = {left_factor, right_factor};
  impl_->ApplySetPoints();
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
  const mjtNum* qvel = impl_->d->qvel + impl_->ids.root_dofadr;
  const double yaw = impl_->X_WA().theta;
  // Free joint: linear velocity of the body origin (the axle centre) in W,
  // then angular velocity in the body frame (its z is ~vertical).
  Twist2 twist;
  twist.v_mps = qvel[0] * std::cos(yaw) + qvel[1] * std::sin(yaw);
  twist.w_radps = qvel[5];
  return twist;
}

std::array<double, 2> Simulator::WheelAngles() const {
  const internal::RobotIndices& ids = impl_->ids;
  return {impl_->d->qpos[ids.wheel_qposadr[0]], impl_->d->qpos[ids.wheel_qposadr[1]]};
}

std::array<double, 2> Simulator::WheelVelocities() const {
  const internal::RobotIndices& ids = impl_->ids;
  return {impl_->d->qvel[ids.wheel_dofadr[0]], impl_->d->qvel[ids.wheel_dofadr[1]]};
}

LaserScan Simulator::CastLaser(const LaserParams& laser,
                               const std::vector<double>& beam_angle_offsets_rad,
                               LaserFootprint* footprint) const {
  laser.ValidateOrThrow();
  if (!beam_angle_offsets_rad.empty() &&
      static_cast<int>(beam_angle_offsets_rad.size()) != laser.num_beams) {
    throw SimError("CastLaser: " + std::to_string(beam_angle_offsets_rad.size()) +
                   " beam angle offsets for " + std::to_string(laser.num_beams) + " beams");
  }
  // The beams are cast in the full scene (the static poses kept by
  // LocalGeoms, or mj_ray on the full model while it is the one stepped),
  // from the laser site of the physics being stepped.
  const mjModel* m = impl_->model.get();
  const mjData* d = impl_->data.get();

  LaserScan scan;
  scan.t_s = d->time;
  scan.angle_min_rad = laser.AngleMinRad();
  scan.angle_increment_rad = laser.AngleIncrementRad();
  scan.max_range_m = laser.max_range_m;
  scan.ranges_m.assign(laser.num_beams, laser.max_range_m);
  scan.has_return.assign(laser.num_beams, 0);

  // Every geom group but the robot's; static (world body) geoms included.
  mjtByte geom_groups[mjNGROUP];
  LaserGeomGroups(geom_groups);
  const internal::LocalGeoms* local =
      impl_->local_geoms_on ? &*impl_->local_geoms : nullptr;
  const Pose2 X_WS = this->X_WS();
  const mjtNum origin[3] = {X_WS.x, X_WS.y, impl_->d->site_xpos[3 * impl_->ids.laser_site + 2]};
  const double* offsets = beam_angle_offsets_rad.empty() ? nullptr : beam_angle_offsets_rad.data();
  double* ranges = scan.ranges_m.data();
  auto* has_return = scan.has_return.data();
  // The range of one ray at world bearing `bearing_W`; max_range_m for no echo.
  auto cast = [&](double bearing_W) {
    const mjtNum direction[3] = {std::cos(bearing_W), std::sin(bearing_W), 0.0};
    int geom = -1;
    const mjtNum distance =
        local != nullptr ? local->CastRay(*m, *d, origin, direction, laser.max_range_m)
                         : mj_ray(m, d, origin, direction, geom_groups, 1, -1, &geom);
    return distance >= 0.0 && distance < laser.max_range_m ? static_cast<double>(distance)
                                                           : laser.max_range_m;
  };
  const int rays = footprint != nullptr && laser.HasMixedPixels() ? laser.footprint_rays : 0;
  const bool incidence = footprint != nullptr && laser.HasGrazingDropouts();
  if (footprint != nullptr) {
    footprint->rays_per_beam = rays;
    footprint->sub_ranges_m.assign(static_cast<std::size_t>(laser.num_beams) * rays,
                                   laser.max_range_m);
    footprint->incidence_rad.assign(incidence ? laser.num_beams : 0,
                                    std::numeric_limits<double>::quiet_NaN());
  }
  const double divergence = DegToRad(laser.beam_divergence_deg);
  // One trapped call for the sweep; its body touches plain data only.
  CallMujoco("casting the laser", [&] {
    for (int i = 0; i < laser.num_beams; ++i) {
      const double offset = offsets == nullptr ? 0.0 : offsets[i];
      const double bearing_W = X_WS.theta + scan.BeamAngle(i) + offset;
      const double distance = cast(bearing_W);
      if (distance < laser.max_range_m) {
        ranges[i] = distance;
        has_return[i] = 1;
      }
      // The footprint's sub-rays, evenly from -divergence/2 to +divergence/2.
      for (int j = 0; j < rays; ++j) {
        const double sub = divergence * (static_cast<double>(j) / (rays - 1) - 0.5);
        footprint->sub_ranges_m[static_cast<std::size_t>(i) * rays + j] = cast(bearing_W + sub);
      }
      // The incidence: the beam against the normal of the chord through the
      // hits of two probes either side of it.
      if (incidence && has_return[i]) {
        const double probe = LaserFootprint::kProbeRad;
        const double r_minus = cast(bearing_W - probe);
        const double r_plus = cast(bearing_W + probe);
        if (r_minus < laser.max_range_m && r_plus < laser.max_range_m) {
          const double tx = r_plus * std::cos(bearing_W + probe) -
                            r_minus * std::cos(bearing_W - probe);
          const double ty = r_plus * std::sin(bearing_W + probe) -
                            r_minus * std::sin(bearing_W - probe);
          const double length = std::hypot(tx, ty);
          if (length > 0.0) {
            // |u x t| / |t| is the cosine of the angle between u and the normal.
            const double cos_incidence = std::min(
                std::abs(std::cos(bearing_W) * ty - std::sin(bearing_W) * tx) / length, 1.0);
            footprint->incidence_rad[i] = std::acos(cos_incidence);
          }
        }
      }
    }
  });
  return scan;
}

void Simulator::SetLocalWorldGeoms(bool on) {
  Impl& r = *impl_;
  if (!on && r.local_geoms_on) r.local_geoms->RestoreContacts(r.model.get(), r.data.get());
  if (r.local_physics) r.UseLocalPhysics(on);
  r.local_geoms_on = on;
}

bool Simulator::local_world_geoms() const { return impl_->local_geoms_on; }

bool Simulator::steps_local_model() const { return impl_->UsingLocalPhysics(); }

const std::string& Simulator::local_model_problem() const { return impl_->local_model_problem; }

int Simulator::CountRobotWorldContacts() const { return impl_->CountRobotWorldContacts(); }

const RobotParams& Simulator::robot() const { return impl_->robot; }
const Scene& Simulator::scene() const { return impl_->scene; }

std::vector<double> Simulator::QPos() const {
  return std::vector<double>(impl_->d->qpos, impl_->d->qpos + impl_->m->nq);
}

}  // namespace mjslam::sim
