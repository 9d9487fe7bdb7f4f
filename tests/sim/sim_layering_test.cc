// Layering of sim/: only the MuJoCo adapter (scene.cc, simulator.cc,
// mujoco_errors.cc, local_geoms.cc and the internal scene_model.h and
// local_geoms.h) includes MuJoCo; the pure
// parts and every public header stay MuJoCo-free (sim/README.md).

#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace mjslam::sim {
namespace {

std::string ReadSource(const std::string& relative_path) {
  std::ifstream file(std::string(MJSLAM_SOURCE_DIR) + "/" + relative_path);
  EXPECT_TRUE(file.good()) << relative_path;
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

TEST(SimLayeringTest, OnlyTheMujocoAdapterIncludesMujoco) {
  for (const char* file :
       {"sim/sim_params.h", "sim/sim_params.cc", "sim/diff_drive.h", "sim/diff_drive.cc",
        "sim/laser_noise.h", "sim/laser_noise.cc", "sim/laser_footprint.h", "sim/wheel_odometry.h",
        "sim/wheel_odometry.cc", "sim/obstacles.h", "sim/obstacles.cc", "sim/simulator.h",
        "sim/scene.h", "sim/mujoco_errors.h"}) {
    const std::string text = ReadSource(file);
    EXPECT_EQ(text.find("#include <mujoco"), std::string::npos) << file;
    EXPECT_EQ(text.find("mjModel"), std::string::npos) << file;
    EXPECT_EQ(text.find("scene_model.h"), std::string::npos) << file;
  }
  for (const char* file :
       {"sim/simulator.cc", "sim/scene.cc", "sim/mujoco_errors.cc", "sim/scene_model.h",
        "sim/local_geoms.h", "sim/local_geoms.cc"}) {
    EXPECT_NE(ReadSource(file).find("#include <mujoco/mujoco.h>"), std::string::npos) << file;
  }
}

}  // namespace
}  // namespace mjslam::sim
