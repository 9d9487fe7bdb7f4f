#pragma once

// Helpers shared by the sim tests: inline MJCF worlds written to temporary
// files, the robot model's path, and a fixture that installs the MuJoCo
// error and warning handlers (sim/mujoco_errors.h) and cleans up.

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

#include "sim/mujoco_errors.h"

namespace mjslam::sim::testing {

/// The shipped robot model.
inline std::string RobotModelPath() {
  return std::string(MJSLAM_SOURCE_DIR) + "/models/pioneer3dx.xml";
}

/// A shipped world by file name (e.g. "room.xml").
inline std::string WorldPath(const std::string& name) {
  return std::string(MJSLAM_SOURCE_DIR) + "/worlds/" + name;
}

/// This test process's own directory for inline worlds, under the system's
/// temp directory (removed by MujocoTest::TearDown).
inline std::filesystem::path TempDir() {
  return std::filesystem::temp_directory_path() /
         ("mjslam_sim_test_" + std::to_string(::getpid()));
}

/// Writes `text` to `name` in TempDir() and returns the file's path.
inline std::string WriteTempFile(const std::string& name, const std::string& text) {
  const std::filesystem::path dir = TempDir();
  std::filesystem::create_directories(dir);
  const std::filesystem::path path = dir / name;
  std::ofstream file(path);
  file << text;
  return path.string();
}

/// A world MJCF: a floor plane, a start site at the origin facing +x, and
/// `body` inserted into <worldbody>.
inline std::string WorldXml(const std::string& body,
                            const std::string& start = "<site name=\"start\" pos=\"0 0 0\"/>") {
  return "<mujoco model=\"test_world\">\n  <worldbody>\n"
         "    <geom name=\"floor\" type=\"plane\" size=\"50 50 0.1\"/>\n    " +
         start + "\n    " + body + "\n  </worldbody>\n</mujoco>\n";
}

/// A world the scene accepts but the physics rejects: no floor (the robot
/// does not come to rest).
inline std::string NoFloorWorldXml() {
  return "<mujoco><worldbody><site name=\"start\"/></worldbody></mujoco>";
}

/// A world the scene accepts but the physics rejects: the start pose puts
/// the robot's rear into the geom 'wall'.
inline std::string StartInWallWorldXml() {
  return WorldXml("<geom name=\"wall\" type=\"box\" size=\"0.1 2 0.5\" pos=\"-0.2 0 0.5\"/>");
}

/// Whether `text` contains `part`.
inline bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// Installs the MuJoCo error and warning handlers before each test (so a
/// MuJoCo error or warning in any trapped call becomes a SimError, which
/// fails a test that does not expect it, and one outside a trapped call
/// aborts the test program), and removes the test's temporary files
/// afterwards.
class MujocoTest : public ::testing::Test {
 protected:
  void SetUp() override { InstallMujocoErrorHandlers(); }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(TempDir(), ignored);
  }
};

}  // namespace mjslam::sim::testing
