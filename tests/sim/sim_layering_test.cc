// Layering of sim/: only simulator.cc includes MuJoCo; the pure parts and
// every public header stay MuJoCo-free (sim/README.md).

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

TEST(SimLayeringTest, OnlySimulatorCcIncludesMujoco) {
  for (const char* file :
       {"sim/sim_params.h", "sim/sim_params.cc", "sim/diff_drive.h", "sim/diff_drive.cc",
        "sim/laser_noise.h", "sim/laser_noise.cc", "sim/wheel_odometry.h",
        "sim/wheel_odometry.cc", "sim/obstacles.h", "sim/obstacles.cc", "sim/simulator.h"}) {
    const std::string text = ReadSource(file);
    EXPECT_EQ(text.find("#include <mujoco"), std::string::npos) << file;
    EXPECT_EQ(text.find("mjModel"), std::string::npos) << file;
  }
  EXPECT_NE(ReadSource("sim/simulator.cc").find("#include <mujoco/mujoco.h>"), std::string::npos);
}

}  // namespace
}  // namespace mjslam::sim
