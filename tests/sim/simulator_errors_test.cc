// The simulator's own checks give a clear SimError naming the file; MuJoCo's
// errors and warnings inside the physics become SimErrors with MuJoCo's
// message (the scene's checks: tests/sim/scene_test.cc).

#include <string>

#include <gtest/gtest.h>

#include "common/params.h"
#include "sim/simulator.h"
#include "tests/sim/sim_test_util.h"

namespace mjslam::sim {
namespace {

using testing::Contains;
using testing::MujocoTest;
using testing::RobotModelPath;
using testing::WorldXml;
using testing::WriteTempFile;

// The message of the SimError that constructing a Simulator throws ("" if none).
std::string LoadError(const std::string& world, const SimParams& sim = {},
                      const RobotParams& robot = {},
                      std::optional<Pose2> start = std::nullopt,
                      const std::string& robot_model = RobotModelPath()) {
  try {
    Simulator simulator(world, robot_model, sim, robot, start);
  } catch (const SimError& error) {
    return error.what();
  }
  return "";
}

// See MujocoErrorInsideAPhysicsCall... below. With MuJoCo 2.2.2, the
// compiler needs an nstack of at least 165 and the placed robot 192.
constexpr char kTinyStackWorld[] = R"(<mujoco>
  <size nstack="178"/>
  <worldbody>
    <geom name="floor_box" type="box" size="5 5 0.1" pos="10 0 -0.1"/>
    <site name="start" pos="10 0 0"/>
  </worldbody>
</mujoco>
)";

// An empty world (floor and start) with MuJoCo <size> attributes.
std::string WorldWithSize(const std::string& size_attributes) {
  return "<mujoco>\n  <size " + size_attributes +
         "/>\n  <worldbody>\n    <geom name=\"floor\" type=\"plane\" size=\"50 50 0.1\"/>\n"
         "    <site name=\"start\"/>\n  </worldbody>\n</mujoco>\n";
}

class SimulatorErrorsTest : public MujocoTest {};

TEST_F(SimulatorErrorsTest, ThePathConstructorReportsTheScenesErrors) {
  const std::string message = LoadError("/nonexistent/dir/no_world.xml");
  EXPECT_TRUE(Contains(message, "world file not found")) << message;
  const std::string no_start = LoadError(WriteTempFile("no_start.xml", WorldXml("", "")));
  EXPECT_TRUE(Contains(no_start, "no site named 'start'")) << no_start;
  // Not even a start pose given explicitly makes such a world valid.
  EXPECT_FALSE(LoadError(WriteTempFile("no_start.xml", WorldXml("", "")), {}, {},
                         Pose2(0, 0, 0)).empty());
}

TEST_F(SimulatorErrorsTest, RobotParamsThatDisagreeWithTheModel) {
  const std::string world = WriteTempFile("params_world.xml", WorldXml(""));
  RobotParams robot;
  robot.wheel_radius_m = 0.09;
  const std::string radius_message = LoadError(world, {}, robot);
  EXPECT_TRUE(Contains(radius_message, "wheel_radius_m")) << radius_message;
  EXPECT_TRUE(Contains(radius_message, "pioneer3dx.xml")) << radius_message;
  robot = RobotParams{};
  robot.axle_track_m = 0.36;
  EXPECT_TRUE(Contains(LoadError(world, {}, robot), "axle_track_m"));
  // Within 1 mm is accepted.
  robot = RobotParams{};
  robot.axle_track_m += 0.0009;
  EXPECT_EQ(LoadError(world, {}, robot), "");
}

TEST_F(SimulatorErrorsTest, InvalidParamsThrowParamError) {
  const std::string world = WriteTempFile("params_world.xml", WorldXml(""));
  SimParams sim;
  sim.timestep_s = 0.0;
  EXPECT_THROW(Simulator(world, RobotModelPath(), sim, RobotParams{}), ParamError);
  RobotParams robot;
  robot.control_point_offset_m = -0.1;
  EXPECT_THROW(Simulator(world, RobotModelPath(), SimParams{}, robot), ParamError);
}

TEST_F(SimulatorErrorsTest, UnstableWheelGainIsRejected) {
  const std::string world = WriteTempFile("params_world.xml", WorldXml(""));
  SimParams sim;
  sim.wheel_speed_kp_nms_per_rad = 100.0;
  EXPECT_TRUE(Contains(LoadError(world, sim), "unstable")) << LoadError(world, sim);
}

TEST_F(SimulatorErrorsTest, StartPoseInCollision) {
  const std::string message =
      LoadError(WriteTempFile("collision_world.xml", testing::StartInWallWorldXml()));
  EXPECT_TRUE(Contains(message, "in collision")) << message;
  EXPECT_TRUE(Contains(message, "'wall'")) << message;
}

TEST_F(SimulatorErrorsTest, WorldWithoutFloor) {
  const std::string message = LoadError(WriteTempFile("no_floor.xml", testing::NoFloorWorldXml()));
  EXPECT_TRUE(Contains(message, "did not come to rest")) << message;
}

// A world whose MuJoCo stack (MJCF <size nstack>) is big enough for the
// compiler's mj_forward (the robot at the model's origin, in the air: the
// floor is a box away from the origin) but too small for the contacts at the
// start on that floor: MuJoCo raises an error inside mj_forward while the
// robot is placed. The caller gets a SimError carrying MuJoCo's message, and
// the process goes on simulating afterwards.
TEST_F(SimulatorErrorsTest, MujocoErrorInsideAPhysicsCallBecomesASimErrorAndTheProcessGoesOn) {
  const std::string world = WriteTempFile("tiny_stack.xml", kTinyStackWorld);
  const Scene scene(world, RobotModelPath());  // no physics yet: loads
  std::string message;
  try {
    Simulator simulator(scene, SimParams{}, RobotParams{});
  } catch (const SimError& error) {
    message = error.what();
  }
  EXPECT_TRUE(Contains(message, "placing the robot in world ")) << message;
  EXPECT_TRUE(Contains(message, "tiny_stack.xml")) << message;
  EXPECT_TRUE(Contains(message, ": MuJoCo error: Stack overflow")) << message;  // MuJoCo's words
  for (int run = 0; run < 2; ++run) {
    Simulator sim(WriteTempFile("fine.xml", WorldXml("")), RobotModelPath(), SimParams{},
                  RobotParams{});
    sim.SetCommand({0.3, 0.0});
    sim.Advance(1.0);
    EXPECT_GT(sim.X_WR().x, 0.1);
  }
}

// A contact buffer too small for the robot's wheels and caster on the
// floor: MuJoCo warns (and goes on) inside the first step; the warning
// becomes a SimError.
TEST_F(SimulatorErrorsTest, MujocoWarningInsideAStepBecomesASimError) {
  const std::string world = WriteTempFile(
      "tiny_contacts.xml", WorldWithSize("nconmax=\"1\""));
  const std::string message = LoadError(world);
  EXPECT_TRUE(Contains(message, "MuJoCo warning: ")) << message;
  EXPECT_TRUE(Contains(message, "tiny_contacts.xml")) << message;
}

}  // namespace
}  // namespace mjslam::sim
