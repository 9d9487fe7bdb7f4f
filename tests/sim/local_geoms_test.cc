// The simulator's local contacts and beams (sim/local_geoms.h) give MuJoCo's
// answers: every beam agrees with mj_ray (the same simulator with
// SetLocalWorldGeoms(false)) to 1e-9 m, and in fact bit for bit, in every
// shipped world and in a seeded clutter of 400 geoms of every primitive type;
// and the physics with local contacts is bit-identical to MuJoCo's
// all-pairs collision, crashes into walls included.

#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/rng.h"
#include "sim/scene.h"
#include "sim/simulator.h"
#include "tests/sim/sim_test_util.h"

namespace mjslam::sim {
namespace {

using testing::MujocoTest;
using testing::RobotModelPath;
using testing::WorldPath;
using testing::WriteTempFile;

// Stations with 1.2 m of clear floor around them in the clutter world.
std::vector<Eigen::Vector2d> ClutterStations() {
  std::vector<Eigen::Vector2d> stations;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 4; ++j) stations.emplace_back(-16.0 + 8.0 * i, -11.0 + 7.0 * j);
  }
  return stations;
}

// A seeded 40 x 30 m clutter: rotated boxes (walls and columns), cylinders,
// capsules, spheres and ellipsoids at random heights (some below or above
// the beam plane), plus the cases mj_ray treats specially: an invisible geom,
// a geom whose material is invisible, a geom in group 4, a geom that does not
// collide, and geoms on a static child body. None within 1.2 m of a station.
// `upright`: boxes and cylinders only, standing on the floor, turned about z
// only (the robot can run into them without climbing). `child_bodies`: with
// the static child bodies (without them, the world gets a local physics
// model: sim/local_physics.h).
std::string ClutterWorld(std::uint64_t seed, bool upright = false, bool child_bodies = true) {
  Rng rng(seed);
  const std::vector<Eigen::Vector2d> stations = ClutterStations();
  std::ostringstream xml;
  xml.precision(17);
  xml << "<mujoco model=\"clutter\">\n<asset><material name=\"glass\" rgba=\"1 1 1 0\"/>"
         "<material name=\"paint\" rgba=\"0.5 0.5 0.5 1\"/></asset>\n<worldbody>\n"
         "<geom name=\"floor\" type=\"plane\" size=\"30 25 0.1\"/>\n"
         "<site name=\"start\" pos=\"" << stations[0].x() << " " << stations[0].y() << " 0\"/>\n";
  const char* kTypes[] = {"box", "box", "box", "cylinder", "capsule", "sphere", "ellipsoid"};
  int placed = 0;
  while (placed < 400) {
    const Eigen::Vector2d p(rng.Uniform() * 40.0 - 20.0, rng.Uniform() * 30.0 - 15.0);
    const std::string type = kTypes[static_cast<int>(rng.Uniform() * (upright ? 4 : 7))];
    const double a = 0.05 + rng.Uniform() * (type == "box" ? 3.0 : 0.5);
    const double b = 0.05 + rng.Uniform() * 0.4;
    const double c = 0.1 + rng.Uniform() * 0.6;
    const double z = upright || rng.Uniform() < 0.8 ? c : (rng.Uniform() < 0.5 ? -0.5 : 1.2);
    const double tilt = upright ? 0.0 : 40.0;
    bool clear = true;
    for (const Eigen::Vector2d& s : stations) clear = clear && (p - s).norm() > 1.2 + a + b + c;
    if (!clear) continue;
    xml << "<geom type=\"" << type << "\" size=\"" << a << " " << b << " " << c << "\" pos=\""
        << p.x() << " " << p.y() << " " << z << "\" euler=\"" << (rng.Uniform() - 0.5) * tilt << " "
        << (rng.Uniform() - 0.5) * tilt << " " << rng.Uniform() * 360 << "\"";
    switch (placed % 10) {
      case 1: xml << " rgba=\"1 0 0 0\""; break;
      case 2: xml << " material=\"glass\""; break;
      case 3: xml << " material=\"paint\" rgba=\"1 0 0 0\""; break;
      case 4: xml << " group=\"4\""; break;
      case 5: xml << " contype=\"0\" conaffinity=\"0\""; break;
      default: break;
    }
    xml << "/>\n";
    if (child_bodies && placed % 50 == 7) {
      xml << "<body pos=\"" << p.x() << " " << p.y() << " 0.5\" euler=\"0 0 33\">"
          << "<geom type=\"box\" size=\"0.3 0.1 0.4\" pos=\"0.2 0.1 0\" euler=\"0 0 20\"/></body>\n";
    }
    ++placed;
  }
  xml << "</worldbody>\n</mujoco>\n";
  return WriteTempFile("clutter_" + std::to_string(seed) + (upright ? "_upright" : "") +
                           (child_bodies ? "" : "_flat") + ".xml",
                       xml.str());
}

// Largest |local - mj_ray| over every beam of `num_yaws` sweeps from each
// pose (yaws 0, 2 pi / num_yaws, ...; jittered beams), and the number of
// beams that differ at all.
struct Agreement {
  double max_difference_m = 0.0;
  int beams = 0;
  int returns = 0;
  int differing = 0;
};

void CompareSweeps(const std::string& world, const std::vector<Pose2>& poses,
                   const LaserParams& laser, Agreement* agreement) {
  Rng rng(11);
  const Scene scene(world, RobotModelPath());
  for (const Pose2& pose : poses) {
    Simulator sim(scene, SimParams{}, RobotParams{}, pose);
    std::vector<double> offsets(laser.num_beams);
    for (double& offset : offsets) offset = DegToRad(rng.Gaussian(0.0, 0.3));
    ASSERT_TRUE(sim.local_world_geoms());
    const LaserScan local = sim.CastLaser(laser, offsets);
    sim.SetLocalWorldGeoms(false);
    const LaserScan brute = sim.CastLaser(laser, offsets);
    for (int b = 0; b < laser.num_beams; ++b) {
      const double difference = std::abs(local.ranges_m[b] - brute.ranges_m[b]);
      agreement->max_difference_m = std::max(agreement->max_difference_m, difference);
      agreement->differing += local.ranges_m[b] != brute.ranges_m[b] ||
                              local.has_return[b] != brute.has_return[b];
      agreement->returns += brute.has_return[b];
      ++agreement->beams;
    }
  }
}

// Poses at a world's tour waypoints (or its start), facing four ways.
std::vector<Pose2> TourPoses(const std::string& world) {
  const Scene scene(world, RobotModelPath());
  std::vector<Pose2> poses;
  std::vector<Eigen::Vector2d> points = scene.TourWaypoints();
  if (points.empty()) points.push_back(scene.StartPose().translation());
  for (const Eigen::Vector2d& p : points) {
    for (int k = 0; k < 4; ++k) poses.emplace_back(p.x(), p.y(), 0.3 + k * kPi / 2);
  }
  return poses;
}

class LocalGeomsTest : public MujocoTest {};

TEST_F(LocalGeomsTest, EveryBeamOfEveryShippedWorldAgreesWithMjRay) {
  int worlds = 0;
  for (const auto& entry : std::filesystem::directory_iterator(WorldPath(""))) {
    if (entry.path().extension() != ".xml") continue;
    ++worlds;
    for (const double max_range : {30.0, 3.0}) {
      LaserParams laser;
      laser.max_range_m = max_range;
      Agreement agreement;
      CompareSweeps(entry.path().string(), TourPoses(entry.path().string()), laser, &agreement);
      EXPECT_LE(agreement.max_difference_m, 1e-9) << entry.path();
      EXPECT_EQ(agreement.differing, 0) << entry.path() << " max range " << max_range;
      EXPECT_GT(agreement.returns, 0) << entry.path();
      std::cout << entry.path().filename() << " max range " << max_range << " m: "
                << agreement.beams << " beams, " << agreement.returns << " returns, largest "
                << "difference " << agreement.max_difference_m << " m\n";
    }
  }
  EXPECT_GE(worlds, 4);
}

TEST_F(LocalGeomsTest, EveryBeamInASeededClutterOfEveryGeomTypeAgreesWithMjRay) {
  for (const std::uint64_t seed : {1u, 2u}) {
    const std::string world = ClutterWorld(seed);
    std::vector<Pose2> poses;
    for (const Eigen::Vector2d& s : ClutterStations()) {
      for (int k = 0; k < 3; ++k) poses.emplace_back(s.x(), s.y(), 0.1 + k * 2.1);
    }
    Agreement agreement;
    CompareSweeps(world, poses, LaserParams{}, &agreement);
    EXPECT_LE(agreement.max_difference_m, 1e-9) << "seed " << seed;
    EXPECT_EQ(agreement.differing, 0) << "seed " << seed;
    // Most beams hit something: the clutter is dense.
    EXPECT_GT(agreement.returns, agreement.beams / 2) << "seed " << seed;
  }
}

// Two simulators, local contacts on and off, under the same seeded commands
// (1.5 s forward at 0.8 m/s, a stop, 0.3 s back, random turn rates: the robot runs into
// things many times, from a distance): the same state after every control
// step, bit for bit, and the same contacts.
// With `child_bodies` the world has no local physics model (the full scene
// with far contacts off is stepped); without, the local model is.
void ExpectBitIdenticalThroughCrashes(bool child_bodies) {
  const std::string world = ClutterWorld(3, /*upright=*/true, child_bodies);
  const Scene scene(world, RobotModelPath());
  Simulator local(scene, SimParams{}, RobotParams{});
  Simulator brute(scene, SimParams{}, RobotParams{});
  brute.SetLocalWorldGeoms(false);
  ASSERT_EQ(local.steps_local_model(), !child_bodies) << local.local_model_problem();
  Rng rng(5);
  int crashes = 0;
  bool in_contact = false;
  double turn_rate = 0.0;
  for (int step = 0; step < 500; ++step) {
    if (step % 20 == 0) turn_rate = rng.Gaussian(0.0, 1.0);
    const int phase = step % 20;
    const Twist2 command{phase < 15 ? 0.8 : (phase < 17 ? 0.0 : -0.3), turn_rate};
    local.SetCommand(command);
    brute.SetCommand(command);
    local.Advance(0.1);
    brute.Advance(0.1);
    ASSERT_EQ(local.QPos(), brute.QPos()) << "step " << step;
    const int contacts = local.CountRobotWorldContacts();
    ASSERT_EQ(contacts, brute.CountRobotWorldContacts()) << "step " << step;
    crashes += contacts > 0 && !in_contact;
    in_contact = contacts > 0;
  }
  // The drive did run into obstacles, many times.
  EXPECT_GE(crashes, 15);
  std::cout << crashes << " crashes in 500 control steps\n";
}

TEST_F(LocalGeomsTest, LocalContactsGiveBitIdenticalPhysicsThroughCrashes) {
  ExpectBitIdenticalThroughCrashes(/*child_bodies=*/true);
}

TEST_F(LocalGeomsTest, TheLocalPhysicsModelGivesBitIdenticalPhysicsThroughCrashes) {
  ExpectBitIdenticalThroughCrashes(/*child_bodies=*/false);
}

// Head on (and at 30 degrees) into an axis-aligned wall at 1.2 m/s, from
// starts 2 cm apart over one refresh distance (0.25 m), so that the last
// refresh before the wall falls at every distance from it: the same state
// as MuJoCo's all-pairs collision at every control step.
TEST_F(LocalGeomsTest, LocalContactsCatchAWallWhereverTheLastRefreshFell) {
  const std::string world = WriteTempFile(
      "wall_world.xml",
      testing::WorldXml("<geom name=\"wall\" type=\"box\" size=\"0.1 3 0.5\" pos=\"2.1 0 0.5\"/>"));
  const Scene scene(world, RobotModelPath());
  int runs_in_contact = 0;
  for (const double yaw : {0.0, DegToRad(30.0)}) {
    for (int k = 0; k < 13; ++k) {
      const Pose2 start(0.02 * k, 0.0, yaw);
      Simulator local(scene, SimParams{}, RobotParams{}, start);
      Simulator brute(scene, SimParams{}, RobotParams{}, start);
      brute.SetLocalWorldGeoms(false);
      bool touched = false;
      for (int step = 0; step < 25; ++step) {
        local.SetCommand({1.2, 0.0});
        brute.SetCommand({1.2, 0.0});
        local.Advance(0.1);
        brute.Advance(0.1);
        ASSERT_EQ(local.QPos(), brute.QPos()) << "start x " << start.x << " step " << step;
        ASSERT_EQ(local.CountRobotWorldContacts(), brute.CountRobotWorldContacts());
        touched = touched || local.CountRobotWorldContacts() > 0;
      }
      runs_in_contact += touched;
    }
  }
  EXPECT_EQ(runs_in_contact, 26);
}

}  // namespace
}  // namespace mjslam::sim
