// Keeps the layering of the style guide honest: which folder may include what.
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace mjslam {
namespace {

namespace fs = std::filesystem;

// Project folders that hold code.
const std::set<std::string> kCodeFolders = {"common", "config",   "sim",     "slam",
                                            "explorer", "eval",   "rundir",  "realdata",
                                            "renders", "app",     "fuzz"};

// What each folder may include from the project and from outside.
struct Rule {
  std::set<std::string> project;  // project folders it may include
  bool mujoco = false;  // also sim/scene_model.h, sim/local_geoms.h and sim/local_physics.h, sim's internal headers with MuJoCo types
  bool yaml = false;
  bool gl = false;
  bool files_and_printing = true;  // <fstream>, <iostream>
};

Rule RuleFor(const std::string& folder) {
  if (folder == "common") return {{"common"}, false, false, false, false};
  if (folder == "slam") return {{"common", "slam"}, false, false, false, false};
  if (folder == "explorer") return {{"common", "explorer"}, false, false, false, false};
  if (folder == "eval") return {{"common", "eval"}, false, false, false, false};
  // The run directory's format: common and files. eval/map_types.h is the
  // map feature the map CSVs hold, until one map feature lives in common/.
  if (folder == "rundir") return {{"common", "rundir"}, false, false, false, true};
  // Real logs: read files, know common's poses; not the run directory.
  if (folder == "realdata") return {{"common", "realdata"}, false, false, false, true};
  if (folder == "config") return {{"common", "config"}, false, true, false, true};
  if (folder == "sim") return {{"common", "sim"}, true, false, false, true};
  if (folder == "renders") return {kCodeFolders, true, false, true, true};
  // The fuzz targets read inputs as the program does: config, rundir, real
  // logs, sim's world checks and grid, and app's RunConfig, import and
  // campaigns; no MuJoCo, YAML or GL of their own.
  if (folder == "fuzz") {
    return {{"common", "config", "rundir", "realdata", "sim", "app", "fuzz"}, false, false, false, true};
  }
  return {kCodeFolders, false, false, false, true};  // app
}

// The violations of `rule` in the text of one source file.
std::vector<std::string> Violations(const std::string& text, const Rule& rule) {
  std::vector<std::string> found;
  static const std::regex kInclude(R"(^\s*#\s*include\s*[<"]([^>"]+)[>"])");
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    std::smatch match;
    if (!std::regex_search(line, match, kInclude)) continue;
    const std::string header = match[1];
    const std::string top = header.substr(0, header.find('/'));
    const bool nested = header.find('/') != std::string::npos;
    if (nested && kCodeFolders.count(top) > 0 && rule.project.count(top) == 0) {
      found.push_back(header);
    } else if ((top == "mujoco" || header == "sim/scene_model.h" ||
                header == "sim/local_geoms.h" || header == "sim/local_physics.h") &&
               !rule.mujoco) {
      found.push_back(header);
    } else if (top == "yaml-cpp" && !rule.yaml) {
      found.push_back(header);
    } else if ((top == "GL" || top == "EGL") && !rule.gl) {
      found.push_back(header);
    } else if ((header == "fstream" || header == "iostream") && !rule.files_and_printing) {
      found.push_back(header);
    }
  }
  return found;
}

TEST(LayeringTest, DetectsForbiddenIncludes) {
  const std::string text =
      "#include <mujoco/mujoco.h>\n#include \"explorer/waypoint_driver.h\"\n"
      "#include <yaml-cpp/yaml.h>\n#include <GL/osmesa.h>\n#include <fstream>\n"
      "#include \"common/pose2.h\"\n#include <Eigen/Core>\n";
  EXPECT_EQ(Violations(text, RuleFor("slam")).size(), 5u);
  EXPECT_EQ(Violations(text, RuleFor("renders")).size(), 1u);  // yaml-cpp
  EXPECT_TRUE(Violations("#include \"slam/ekf_slam.h\"\n", RuleFor("app")).empty());
  // MuJoCo's types reach app/ neither directly nor through sim's internal
  // header; renders/ may use both.
  const std::string internal = "#include \"sim/scene_model.h\"\n#include \"sim/scene.h\"\n";
  EXPECT_EQ(Violations(internal, RuleFor("app")).size(), 1u);
  EXPECT_EQ(Violations("#include \"sim/local_geoms.h\"\n", RuleFor("app")).size(), 1u);
  EXPECT_EQ(Violations("#include \"sim/local_physics.h\"\n", RuleFor("app")).size(), 1u);
  EXPECT_TRUE(Violations(internal, RuleFor("renders")).empty());
  // rundir/ may write files but knows nothing of MuJoCo, YAML, the filters
  // or the program.
  EXPECT_EQ(Violations(text, RuleFor("rundir")).size(), 4u);
  EXPECT_EQ(Violations("#include \"app/run.h\"\n#include \"slam/ekf_slam.h\"\n",
                       RuleFor("rundir")).size(),
            2u);
  // ... and the core folders may not write run directories.
  EXPECT_EQ(Violations("#include <fstream>\n#include \"rundir/layout.h\"\n", RuleFor("eval")).size(),
            2u);
}

TEST(LayeringTest, EveryFolderIncludesOnlyWhatItMay) {
  const fs::path root(MJSLAM_SOURCE_DIR);
  int files = 0;
  for (const std::string& folder : kCodeFolders) {
    if (!fs::exists(root / folder)) continue;
    for (const auto& entry : fs::recursive_directory_iterator(root / folder)) {
      const std::string ext = entry.path().extension().string();
      if (ext != ".h" && ext != ".cc") continue;
      std::ifstream in(entry.path());
      std::stringstream text;
      text << in.rdbuf();
      ++files;
      for (const std::string& header : Violations(text.str(), RuleFor(folder))) {
        ADD_FAILURE() << entry.path() << " includes " << header << ", which " << folder
                      << "/ may not";
      }
    }
  }
  EXPECT_GT(files, 10);
}

// The closed-loop engine (app/closed_loop.*) runs the simulator or a
// recording, the filters and the driver; it writes no files, prints nothing
// and knows nothing of rendering or YAML (its callers do).
TEST(LayeringTest, ClosedLoopWritesNoFilesAndDoesNotRender) {
  const Rule rule = {{"common", "sim", "slam", "explorer", "eval", "rundir", "app"},
                     false, false, false, false};
  EXPECT_EQ(Violations("#include \"renders/image.h\"\n#include <fstream>\n", rule).size(), 2u);
  const fs::path root(MJSLAM_SOURCE_DIR);
  for (const char* file : {"app/closed_loop.h", "app/closed_loop.cc"}) {
    std::ifstream in(root / file);
    ASSERT_TRUE(in) << file;
    std::stringstream text;
    text << in.rdbuf();
    for (const std::string& header : Violations(text.str(), rule)) {
      ADD_FAILURE() << file << " includes " << header;
    }
    EXPECT_EQ(text.str().find("printf"), std::string::npos) << file;
    EXPECT_EQ(text.str().find("CsvWriter"), std::string::npos) << file;
  }
}

// The shared test fixtures (tests/support/) stand in for the simulator: they
// may use common/ (and slam/'s observation types for the synthetic feature
// world), but no MuJoCo, yaml-cpp or GL, and no other project folder.
TEST(LayeringTest, TestSupportIncludesOnlyCommonAndSlam) {
  const Rule rule{{"common", "slam"}, false, false, false, true};
  EXPECT_EQ(Violations("#include \"explorer/occupancy_grid.h\"\n", rule).size(), 1u);
  const fs::path folder = fs::path(MJSLAM_SOURCE_DIR) / "tests" / "support";
  int files = 0;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.path().extension() != ".h") continue;
    std::ifstream in(entry.path());
    std::stringstream text;
    text << in.rdbuf();
    ++files;
    for (const std::string& header : Violations(text.str(), rule)) {
      ADD_FAILURE() << entry.path() << " includes " << header << ", which tests/support/ may not";
    }
  }
  EXPECT_GE(files, 5);
}

}  // namespace
}  // namespace mjslam
