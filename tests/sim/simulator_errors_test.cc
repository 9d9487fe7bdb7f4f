// Bad input gives a clear SimError naming the file (and quoting MuJoCo's own
// message where MuJoCo found the problem); MuJoCo's errors become exceptions.

#include <string>

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include "common/params.h"
#include "sim/simulator.h"
#include "tests/sim/sim_test_util.h"

namespace mjslam::sim {
namespace {

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

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

class SimulatorErrorsTest : public MujocoTest {};

TEST_F(SimulatorErrorsTest, MissingWorldFileIsNamed) {
  const std::string message = LoadError("/nonexistent/dir/no_world.xml");
  EXPECT_TRUE(Contains(message, "world file not found")) << message;
  EXPECT_TRUE(Contains(message, "/nonexistent/dir/no_world.xml")) << message;
}

TEST_F(SimulatorErrorsTest, MissingRobotFileIsNamed) {
  const std::string world = WriteTempFile("ok_world.xml", WorldXml(""));
  const std::string message = LoadError(world, {}, {}, std::nullopt, "/nonexistent/robot.xml");
  EXPECT_TRUE(Contains(message, "robot model file not found")) << message;
  EXPECT_TRUE(Contains(message, "/nonexistent/robot.xml")) << message;
}

TEST_F(SimulatorErrorsTest, MalformedXmlQuotesMujocoAndNamesTheFile) {
  const std::string world = WriteTempFile(
      "malformed_world.xml", "<mujoco>\n  <worldbody>\n    <geom type=\"box\"\n</mujoco>\n");
  const std::string message = LoadError(world);
  EXPECT_TRUE(Contains(message, "malformed_world.xml")) << message;
  EXPECT_TRUE(Contains(message, "XML")) << message;  // MuJoCo's "XML Error ..."
}

TEST_F(SimulatorErrorsTest, SchemaViolationQuotesMujocoAndNamesTheFile) {
  const std::string world =
      WriteTempFile("schema_world.xml", WorldXml("<geom type=\"box\" sise=\"1 1 1\"/>"));
  const std::string message = LoadError(world);
  EXPECT_TRUE(Contains(message, "schema_world.xml")) << message;
  EXPECT_TRUE(Contains(message, "sise")) << message;  // MuJoCo names the bad attribute
}

TEST_F(SimulatorErrorsTest, WorldWithoutStartSite) {
  const std::string world = WriteTempFile("no_start.xml", WorldXml("", ""));
  const std::string message = LoadError(world);
  EXPECT_TRUE(Contains(message, "no site named 'start'")) << message;
  EXPECT_TRUE(Contains(message, "no_start.xml")) << message;
  // Not even a start pose given explicitly makes such a world valid.
  EXPECT_FALSE(LoadError(world, {}, {}, Pose2(0, 0, 0)).empty());
}

TEST_F(SimulatorErrorsTest, WorldUsingTheRobotGeomGroup) {
  const std::string world = WriteTempFile(
      "group5_world.xml",
      WorldXml("<geom name=\"sneaky\" type=\"box\" size=\"0.1 1 0.5\" pos=\"3 0 0.5\" "
               "group=\"5\"/>"));
  const std::string message = LoadError(world);
  EXPECT_TRUE(Contains(message, "group 5")) << message;
  EXPECT_TRUE(Contains(message, "'sneaky'")) << message;
  EXPECT_TRUE(Contains(message, "group5_world.xml")) << message;
}

TEST_F(SimulatorErrorsTest, WorldWithAMovingBody) {
  const std::string world = WriteTempFile(
      "joint_world.xml",
      WorldXml("<body name=\"crate\" pos=\"3 0 0.3\"><freejoint name=\"crate_free\"/>"
               "<geom type=\"box\" size=\"0.3 0.3 0.3\"/></body>"));
  const std::string message = LoadError(world);
  EXPECT_TRUE(Contains(message, "static geoms only")) << message;
  EXPECT_TRUE(Contains(message, "crate_free")) << message;
}

TEST_F(SimulatorErrorsTest, TourSitesWithAGapOrABadName) {
  const std::string gap = WriteTempFile(
      "tour_gap.xml", WorldXml("<site name=\"tour_0\" pos=\"1 0 0\"/>"
                               "<site name=\"tour_2\" pos=\"2 0 0\"/>"));
  EXPECT_TRUE(Contains(LoadError(gap), "tour_1 is missing")) << LoadError(gap);
  const std::string bad = WriteTempFile(
      "tour_bad.xml", WorldXml("<site name=\"tour_0\" pos=\"1 0 0\"/>"
                               "<site name=\"tour_last\" pos=\"2 0 0\"/>"));
  EXPECT_TRUE(Contains(LoadError(bad), "tour_last")) << LoadError(bad);
}

TEST_F(SimulatorErrorsTest, TourSitesAreReadInOrder) {
  const std::string world = WriteTempFile(
      "tour_ok.xml", WorldXml("<site name=\"tour_1\" pos=\"2 1 0\"/>"
                              "<site name=\"tour_0\" pos=\"1 0 0\"/>"
                              "<site name=\"tour_2\" pos=\"3 -1 0\"/>"));
  Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{});
  const std::vector<Eigen::Vector2d> tour = sim.TourWaypoints();
  ASSERT_EQ(tour.size(), 3u);
  EXPECT_EQ(tour[0], Eigen::Vector2d(1, 0));
  EXPECT_EQ(tour[1], Eigen::Vector2d(2, 1));
  EXPECT_EQ(tour[2], Eigen::Vector2d(3, -1));
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
  const std::string world = WriteTempFile(
      "collision_world.xml",
      WorldXml("<geom name=\"wall\" type=\"box\" size=\"0.1 2 0.5\" pos=\"-0.2 0 0.5\"/>"));
  const std::string message = LoadError(world);
  EXPECT_TRUE(Contains(message, "in collision")) << message;
  EXPECT_TRUE(Contains(message, "'wall'")) << message;
}

TEST_F(SimulatorErrorsTest, WorldWithoutFloor) {
  const std::string world = WriteTempFile(
      "no_floor.xml", "<mujoco><worldbody><site name=\"start\"/></worldbody></mujoco>");
  const std::string message = LoadError(world);
  EXPECT_TRUE(Contains(message, "did not come to rest")) << message;
}

TEST(MujocoErrorHandlersTest, MujocoErrorsAndWarningsBecomeSimErrors) {
  mju_user_error = nullptr;
  mju_user_warning = nullptr;
  InstallMujocoErrorHandlers();
  EXPECT_THROW(mju_error("test error"), SimError);
  EXPECT_THROW(mju_warning("test warning"), SimError);
  // Handlers installed by the program first are kept.
  mju_user_error = &testing::FailOnMujocoError;
  InstallMujocoErrorHandlers();
  EXPECT_EQ(mju_user_error, &testing::FailOnMujocoError);
  mju_user_error = nullptr;
  mju_user_warning = nullptr;
}

}  // namespace
}  // namespace mjslam::sim
