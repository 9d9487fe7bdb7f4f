// A Scene composes a world with the robot, checks the world's rules and
// reports the start, the tour and the obstacles, all without a physics step.

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include "common/angles.h"
#include "sim/scene.h"
#include "sim/simulator.h"
#include "tests/sim/sim_test_util.h"

namespace mjslam::sim {
namespace {

using testing::Contains;
using testing::MujocoTest;
using testing::RobotModelPath;
using testing::WorldXml;
using testing::WriteTempFile;

// The message of the SimError that loading a Scene throws ("" if none).
std::string SceneError(const std::string& world, const std::string& robot_model = RobotModelPath()) {
  try {
    const Scene scene(world, robot_model);
  } catch (const SimError& error) {
    return error.what();
  }
  return "";
}

// The latest simulated time MuJoCo's control callback has seen, in any
// model (MuJoCo calls it in every mj_forward and mj_step, including the
// compiler's own mj_forward at time 0; never in mj_kinematics).
double latest_control_time_s = 0.0;
void RecordControlTime(const mjModel*, mjData* d) {
  latest_control_time_s = std::max(latest_control_time_s, d->time);
}

class SceneTest : public MujocoTest {
 protected:
  void TearDown() override {
    mjcb_control = nullptr;
    MujocoTest::TearDown();
  }
};

// A rotated wall, an upright pillar, a ball, a tilted box, a start site and
// three tour sites given out of order.
constexpr char kFurniture[] = R"(
    <geom name="wall" type="box" size="1 0.1 0.5" pos="3 1 0.5" euler="0 0 30"/>
    <geom name="pillar" type="cylinder" size="0.2 0.6" pos="-2 1 0.6"/>
    <geom name="ball" type="sphere" size="0.3" pos="0 -3 0.3"/>
    <geom name="tilted" type="box" size="0.2 0.2 0.2" pos="-3 -3 0.3" euler="30 0 0"/>
    <site name="tour_1" pos="2 -1 0"/>
    <site name="tour_0" pos="1 0 0"/>
    <site name="tour_2" pos="-1 -1 0"/>)";
constexpr char kStart[] = R"(<site name="start" pos="1 2 0" euler="0 0 30"/>)";

TEST_F(SceneTest, ReadsTheStartTheTourAndTheObstaclesOfARawStringWorld) {
  const Scene scene(WriteTempFile("furnished.xml", WorldXml(kFurniture, kStart)), RobotModelPath());
  EXPECT_NEAR(scene.StartPose().x, 1.0, 1e-12);
  EXPECT_NEAR(scene.StartPose().y, 2.0, 1e-12);
  EXPECT_NEAR(scene.StartPose().theta, DegToRad(30.0), 1e-12);

  const std::vector<Eigen::Vector2d>& tour = scene.TourWaypoints();
  ASSERT_EQ(tour.size(), 3u);
  EXPECT_EQ(tour[0], Eigen::Vector2d(1, 0));
  EXPECT_EQ(tour[1], Eigen::Vector2d(2, -1));
  EXPECT_EQ(tour[2], Eigen::Vector2d(-1, -1));

  // The floor plane and the robot's geoms are not obstacles.
  const std::vector<ObstacleFootprint>& obstacles = scene.Obstacles();
  ASSERT_EQ(obstacles.size(), 4u);
  const ObstacleFootprint& wall = obstacles[0];
  EXPECT_EQ(wall.name, "wall");
  EXPECT_EQ(wall.shape, ObstacleFootprint::Shape::kRectangle);
  EXPECT_NEAR(wall.X_WO.x, 3.0, 1e-12);
  EXPECT_NEAR(wall.X_WO.y, 1.0, 1e-12);
  EXPECT_NEAR(wall.X_WO.theta, DegToRad(30.0), 1e-12);
  EXPECT_EQ(wall.half_extents_m, Eigen::Vector2d(1.0, 0.1));
  EXPECT_NEAR(wall.z_min_m, 0.0, 1e-12);
  EXPECT_NEAR(wall.z_max_m, 1.0, 1e-12);
  EXPECT_TRUE(wall.exact);
  const ObstacleFootprint& pillar = obstacles[1];
  EXPECT_EQ(pillar.shape, ObstacleFootprint::Shape::kCircle);
  EXPECT_DOUBLE_EQ(pillar.radius_m, 0.2);
  EXPECT_NEAR(pillar.z_max_m, 1.2, 1e-12);
  EXPECT_TRUE(pillar.exact);
  const ObstacleFootprint& ball = obstacles[2];
  EXPECT_EQ(ball.shape, ObstacleFootprint::Shape::kCircle);
  EXPECT_DOUBLE_EQ(ball.radius_m, 0.3);
  EXPECT_NEAR(ball.z_min_m, 0.0, 1e-12);
  EXPECT_TRUE(ball.exact);
  // Not upright: only its bounding disc.
  const ObstacleFootprint& tilted = obstacles[3];
  EXPECT_EQ(tilted.shape, ObstacleFootprint::Shape::kCircle);
  EXPECT_NEAR(tilted.radius_m, 0.2 * std::sqrt(3.0), 1e-9);
  EXPECT_FALSE(tilted.exact);
}

TEST_F(SceneTest, ReadsTheRobotModelsWheelGeometry) {
  const Scene scene(WriteTempFile("empty.xml", WorldXml("")), RobotModelPath());
  EXPECT_DOUBLE_EQ(scene.WheelRadiiM()[0], 0.0975);
  EXPECT_DOUBLE_EQ(scene.WheelRadiiM()[1], 0.0975);
  EXPECT_NEAR(scene.AxleTrackM(), 0.33, 1e-12);
  EXPECT_TRUE(Contains(scene.Description(), "empty.xml")) << scene.Description();
  EXPECT_TRUE(Contains(scene.Description(), "pioneer3dx.xml")) << scene.Description();
}

TEST_F(SceneTest, IsBuiltWithoutAPhysicsStep) {
  latest_control_time_s = 0.0;
  mjcb_control = &RecordControlTime;
  // Worlds the physics rejects load as scenes: one without a floor (the
  // robot would fall) and one whose start is inside a wall.
  const Scene no_floor(WriteTempFile("no_floor.xml", testing::NoFloorWorldXml()),
                       RobotModelPath());
  const Scene scene(WriteTempFile("start_in_wall.xml", testing::StartInWallWorldXml()),
                    RobotModelPath());
  EXPECT_EQ(latest_control_time_s, 0.0);
  EXPECT_EQ(scene.Obstacles().size(), 1u);
  // With physics on a scene, simulated time passes (the robot settles).
  EXPECT_THROW(Simulator(no_floor, SimParams{}, RobotParams{}), SimError);
  EXPECT_GT(latest_control_time_s, 0.0);
}

TEST_F(SceneTest, CopiesShareTheLoadedSceneAndOutliveTheOriginal) {
  std::optional<Scene> original(
      Scene(WriteTempFile("furnished.xml", WorldXml(kFurniture, kStart)), RobotModelPath()));
  const Scene copy = *original;
  original.reset();
  EXPECT_EQ(copy.Obstacles().size(), 4u);
  Simulator sim(copy, SimParams{}, RobotParams{});
  EXPECT_NEAR(sim.X_WR().x, 1.0, 1e-3);
}

TEST_F(SceneTest, MissingFilesAreNamed) {
  const std::string missing_world = SceneError("/nonexistent/dir/no_world.xml");
  EXPECT_TRUE(Contains(missing_world, "world file not found")) << missing_world;
  EXPECT_TRUE(Contains(missing_world, "/nonexistent/dir/no_world.xml")) << missing_world;
  const std::string world = WriteTempFile("ok_world.xml", WorldXml(""));
  const std::string missing_robot = SceneError(world, "/nonexistent/robot.xml");
  EXPECT_TRUE(Contains(missing_robot, "robot model file not found")) << missing_robot;
  EXPECT_TRUE(Contains(missing_robot, "/nonexistent/robot.xml")) << missing_robot;
}

TEST_F(SceneTest, MalformedXmlQuotesMujocoAndNamesTheFile) {
  const std::string world = WriteTempFile(
      "malformed_world.xml", "<mujoco>\n  <worldbody>\n    <geom type=\"box\"\n</mujoco>\n");
  const std::string message = SceneError(world);
  EXPECT_TRUE(Contains(message, "malformed_world.xml")) << message;
  EXPECT_TRUE(Contains(message, "XML")) << message;  // MuJoCo's "XML Error ..."
}

TEST_F(SceneTest, SchemaViolationQuotesMujocoAndNamesTheFile) {
  const std::string world =
      WriteTempFile("schema_world.xml", WorldXml("<geom type=\"box\" sise=\"1 1 1\"/>"));
  const std::string message = SceneError(world);
  EXPECT_TRUE(Contains(message, "schema_world.xml")) << message;
  EXPECT_TRUE(Contains(message, "sise")) << message;  // MuJoCo names the bad attribute
}

TEST_F(SceneTest, WorldWithoutStartSite) {
  const std::string message = SceneError(WriteTempFile("no_start.xml", WorldXml("", "")));
  EXPECT_TRUE(Contains(message, "no site named 'start'")) << message;
  EXPECT_TRUE(Contains(message, "no_start.xml")) << message;
}

TEST_F(SceneTest, WorldUsingTheRobotGeomGroup) {
  const std::string world = WriteTempFile(
      "group5_world.xml",
      WorldXml("<geom name=\"sneaky\" type=\"box\" size=\"0.1 1 0.5\" pos=\"3 0 0.5\" "
               "group=\"5\"/>"));
  const std::string message = SceneError(world);
  EXPECT_TRUE(Contains(message, "group 5")) << message;
  EXPECT_TRUE(Contains(message, "'sneaky'")) << message;
  EXPECT_TRUE(Contains(message, "group5_world.xml")) << message;
}

TEST_F(SceneTest, WorldWithAMovingBodyOrAnActuator) {
  const std::string joint = SceneError(WriteTempFile(
      "joint_world.xml",
      WorldXml("<body name=\"crate\" pos=\"3 0 0.3\"><freejoint name=\"crate_free\"/>"
               "<geom type=\"box\" size=\"0.3 0.3 0.3\"/></body>")));
  EXPECT_TRUE(Contains(joint, "static geoms only")) << joint;
  EXPECT_TRUE(Contains(joint, "crate_free")) << joint;
  const std::string actuator = SceneError(WriteTempFile(
      "actuator_world.xml",
      "<mujoco>\n  <worldbody>\n    <geom name=\"floor\" type=\"plane\" size=\"50 50 0.1\"/>\n"
      "    <site name=\"start\"/>\n  </worldbody>\n  <actuator>\n"
      "    <general name=\"extra\" site=\"start\"/>\n  </actuator>\n</mujoco>\n"));
  EXPECT_TRUE(Contains(actuator, "adds actuators")) << actuator;
}

// worlds/README.md: a world must not set <option> (it would be silently
// overridden by, or fight with, the robot model's and the simulator's).
TEST_F(SceneTest, WorldSettingOptionIsRefusedNamingTheElement) {
  for (const char* option : {"<option timestep=\"0.01\"/>", "<option gravity=\"0 0 -1\"/>",
                             "<option><flag contact=\"disable\"/></option>"}) {
    const std::string world_file = WriteTempFile(
        "option_world.xml", std::string("<mujoco>\n  ") + option +
                                "\n  <worldbody>\n    <geom name=\"floor\" type=\"plane\" "
                                "size=\"50 50 0.1\"/>\n    <site name=\"start\"/>\n  "
                                "</worldbody>\n</mujoco>\n");
    const std::string message = SceneError(world_file);
    EXPECT_TRUE(Contains(message, "sets <option>")) << option << ": " << message;
    EXPECT_TRUE(Contains(message, "option_world.xml")) << message;
  }
}

TEST_F(SceneTest, TourSitesWithAGapOrABadName) {
  const std::string gap = SceneError(WriteTempFile(
      "tour_gap.xml", WorldXml("<site name=\"tour_0\" pos=\"1 0 0\"/>"
                               "<site name=\"tour_2\" pos=\"2 0 0\"/>")));
  EXPECT_TRUE(Contains(gap, "tour_1 is missing")) << gap;
  const std::string bad = SceneError(WriteTempFile(
      "tour_bad.xml", WorldXml("<site name=\"tour_0\" pos=\"1 0 0\"/>"
                               "<site name=\"tour_last\" pos=\"2 0 0\"/>")));
  EXPECT_TRUE(Contains(bad, "tour_last")) << bad;
}

TEST_F(SceneTest, RobotModelWithoutALaserSite) {
  const std::string robot = WriteTempFile(
      "no_laser_robot.xml",
      "<mujoco><worldbody><body name=\"r\" pos=\"0 0 0.1\"><freejoint/>"
      "<geom type=\"box\" size=\"0.1 0.1 0.1\" group=\"5\"/></body></worldbody></mujoco>");
  const std::string message = SceneError(WriteTempFile("ok_world.xml", WorldXml("")), robot);
  EXPECT_TRUE(Contains(message, "has no site 'laser'")) << message;
  EXPECT_TRUE(Contains(message, "no_laser_robot.xml")) << message;
}

}  // namespace
}  // namespace mjslam::sim
