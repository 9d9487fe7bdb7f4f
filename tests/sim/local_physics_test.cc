// The local physics model (sim/local_physics.h, sim/README.md "The local
// physics model"): every shipped world gets one; a tour of a shipped world
// is bit-identical to MuJoCo stepping the full scene (tolerance 0 on every
// coordinate of qpos after every control step, and the same contact
// counts); switching to the full scene and back mid-run changes nothing;
// worlds it cannot take say why and still run. (Crashes: local_geoms_test.)

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>

#include <mujoco/mujoco.h>

#include "sim/local_geoms.h"
#include "sim/local_physics.h"
#include "sim/scene.h"
#include "sim/scene_model.h"
#include "sim/simulator.h"
#include "tests/sim/sim_test_util.h"

namespace mjslam::sim {
namespace {

using testing::Contains;
using testing::MujocoTest;
using testing::RobotModelPath;
using testing::WorldPath;
using testing::WriteTempFile;

class LocalPhysicsTest : public MujocoTest {};

TEST_F(LocalPhysicsTest, EveryShippedWorldStepsTheLocalModel) {
  int worlds = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::path(WorldPath("room.xml")).parent_path())) {
    if (entry.path().extension() != ".xml") continue;
    Simulator sim(entry.path().string(), RobotModelPath(), SimParams{}, RobotParams{});
    EXPECT_TRUE(sim.steps_local_model()) << entry.path() << ": " << sim.local_model_problem();
    EXPECT_EQ(sim.local_model_problem(), "");
    sim.SetLocalWorldGeoms(false);
    EXPECT_FALSE(sim.steps_local_model());
    ++worlds;
  }
  EXPECT_GE(worlds, 6);
}

// Drives `local` (the local model) along its world's tour with a point-h
// controller and feeds the same commands to `full` (MuJoCo on the full
// scene): the same qpos after every control step, bit for bit, and the same
// contacts, until the tour is closed or `max_steps` control steps.
void ExpectTourBitIdentical(const std::string& world, int max_steps) {
  const Scene scene(world, RobotModelPath());
  Simulator local(scene, SimParams{}, RobotParams{});
  Simulator full(scene, SimParams{}, RobotParams{});
  full.SetLocalWorldGeoms(false);
  ASSERT_TRUE(local.steps_local_model());
  ASSERT_FALSE(full.steps_local_model());
  const std::vector<Eigen::Vector2d>& tour = scene.TourWaypoints();
  ASSERT_GE(tour.size(), 3u);
  std::size_t target = 1;
  int step = 0;
  for (; step < max_steps && target <= tour.size(); ++step) {
    const Pose2 X_WR = local.X_WR();
    const Eigen::Vector2d error = tour[target % tour.size()] - X_WR.translation();
    if (error.norm() < 0.25) ++target;
    const Eigen::Vector2d velocity = error.normalized() * std::min(0.8, 1.5 * error.norm());
    const double c = std::cos(X_WR.theta);
    const double s = std::sin(X_WR.theta);
    const double a = local.robot().control_point_offset_m;
    const Twist2 command{c * velocity.x() + s * velocity.y(),
                         (-s * velocity.x() + c * velocity.y()) / a};
    local.SetCommand(command);
    full.SetCommand(command);
    local.Advance(0.1);
    full.Advance(0.1);
    ASSERT_EQ(local.QPos(), full.QPos()) << world << " step " << step;
    ASSERT_EQ(local.CountRobotWorldContacts(), full.CountRobotWorldContacts());
  }
  // The tour was driven (a few waypoints at least).
  EXPECT_GE(target, 4u) << world;
  EXPECT_GT(local.time_s(), 20.0);
}

TEST_F(LocalPhysicsTest, ACorridorTourIsBitIdenticalToTheFullScene) {
  ExpectTourBitIdentical(WorldPath("corridor_loop.xml"), 600);
}

TEST_F(LocalPhysicsTest, ABuildingTourIsBitIdenticalToTheFullScene) {
  ExpectTourBitIdentical(WorldPath("building_40x30.xml"), 300);
}

// Switching to the full scene and back mid-run (the state carried each way)
// gives the run it would have been, bit for bit.
TEST_F(LocalPhysicsTest, SwitchingToTheFullSceneAndBackChangesNothing) {
  const std::string world = WriteTempFile(
      "wall_world.xml",
      testing::WorldXml("<geom name=\"wall\" type=\"box\" size=\"0.1 3 0.5\" pos=\"2.1 0 0.5\"/>"));
  const Scene scene(world, RobotModelPath());
  const Pose2 start(0.0, 0.3, 0.5);
  Simulator straight(scene, SimParams{}, RobotParams{}, start);
  Simulator switched(scene, SimParams{}, RobotParams{}, start);
  int contacts = 0;
  for (int step = 0; step < 40; ++step) {
    if (step % 3 == 1) switched.SetLocalWorldGeoms(step % 2 == 0);
    for (Simulator* sim : {&straight, &switched}) {
      sim->SetCommand({1.0, step < 10 ? -0.5 : 0.0});
      sim->Advance(0.1);
    }
    ASSERT_EQ(straight.QPos(), switched.QPos()) << "step " << step;
    ASSERT_EQ(straight.CountRobotWorldContacts(), switched.CountRobotWorldContacts());
    ASSERT_EQ(straight.X_WS().x, switched.X_WS().x);
    contacts += straight.CountRobotWorldContacts() > 0;
  }
  // It did run into the wall.
  EXPECT_GT(contacts, 0);
}

// The local model lists the geom pairs MuJoCo's broadphase would find as
// explicit pairs (opt.collision = mjCOL_PAIR), and they give the contacts
// MuJoCo finds itself in the same model (opt.collision = mjCOL_ALL, no
// pairs), byte for byte, with the robot placed on a 0.37 m grid over the
// corridor loop (in and through its walls too).
TEST_F(LocalPhysicsTest, TheListedPairsGiveTheContactsMujocoFindsItself) {
  const Scene scene(WorldPath("corridor_loop.xml"), RobotModelPath());
  const mjModel& full = internal::SceneAccess::Model(scene);
  const internal::RobotIndices& full_ids = internal::SceneAccess::Robot(scene);
  const internal::DataPtr full_data = internal::MakeData(full, "test");
  mj_forward(&full, full_data.get());
  mjtByte groups[mjNGROUP] = {1, 1, 1, 1, 1, 0};
  const internal::LocalGeoms geoms(full, *full_data, full_ids, groups);
  internal::LocalPhysics local(scene, full, full_ids, geoms);
  ASSERT_EQ(local.problem(), "");
  mjModel* m = local.model();
  mjData* d = local.data();
  ASSERT_EQ(m->opt.collision, mjCOL_PAIR);
  int compared = 0;
  int wall_contacts = 0;
  for (double x = -15.0; x <= 15.0; x += 0.37) {
    for (double y = -15.0; y <= 15.0; y += 0.37) {
      mjtNum* root = d->qpos + local.ids().root_qposadr;
      root[0] = x;
      root[1] = y;
      local.Refresh(full, geoms, root, /*force=*/true);
      mj_forward(m, d);
      const std::vector<mjContact> listed(d->contact, d->contact + d->ncon);
      const int npair = m->npair;
      m->opt.collision = mjCOL_ALL;
      m->npair = 0;
      mj_forward(m, d);
      m->opt.collision = mjCOL_PAIR;
      m->npair = npair;
      ASSERT_EQ(d->ncon, static_cast<int>(listed.size())) << x << ", " << y;
      for (int i = 0; i < d->ncon; ++i) {
        // Every field up to the last (the struct's padding left out).
        ASSERT_EQ(std::memcmp(&listed[i], &d->contact[i],
                              offsetof(mjContact, efc_address) + sizeof(int)),
                  0)
            << x << ", " << y << ", contact " << i;
        wall_contacts += m->geom_type[d->contact[i].geom1] != mjGEOM_PLANE;
      }
      compared += d->ncon;
    }
  }
  EXPECT_GT(compared, 3000);
  EXPECT_GT(wall_contacts, 100);
}

TEST_F(LocalPhysicsTest, WorldsWithoutALocalModelSayWhyAndStillRun) {
  const std::string child_body = WriteTempFile(
      "child_body.xml", testing::WorldXml("<body name=\"shelf\" pos=\"2 0 0.5\"><geom "
                                          "name=\"shelf_box\" type=\"box\" size=\"0.2 0.5 0.5\"/>"
                                          "</body>"));
  const std::string compiler = WriteTempFile(
      "compiler.xml",
      "<mujoco model=\"heavy\">\n  <compiler settotalmass=\"18\"/>\n  <worldbody>\n"
      "    <geom name=\"floor\" type=\"plane\" size=\"50 50 0.1\"/>\n"
      "    <site name=\"start\" pos=\"0 0 0\"/>\n  </worldbody>\n</mujoco>\n");
  for (const auto& [world, why] :
       {std::pair{child_body, "'shelf_box' collides and is not on the world body"},
        std::pair{compiler, "the robot compiles differently alone than with the world (body_"}}) {
    Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{});
    EXPECT_FALSE(sim.steps_local_model());
    EXPECT_TRUE(Contains(sim.local_model_problem(), why)) << sim.local_model_problem();
    sim.SetCommand({0.5, 0.0});
    sim.Advance(1.0);
    EXPECT_GT(sim.X_WR().x, 0.3);
  }
}

}  // namespace
}  // namespace mjslam::sim
