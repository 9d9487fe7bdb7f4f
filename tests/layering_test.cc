// Keeps the layering of the style guide honest: which folder may include what.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace mjslam {
namespace {

namespace fs = std::filesystem;

// Project folders that hold code; app/ is split by job into four folders
// of its own (app/README.md), each a folder here.
const std::set<std::string> kCodeFolders = {
    "common",  "config",  "sim",       "slam",     "explorer",  "eval",      "rundir",
    "realdata", "renders", "app/engine", "app/jobs", "app/batch", "app/cli", "fuzz", "examples",
    "python"};

// The project folder of `path` (a header as included, or a file's path
// relative to the root): "app/<job>" inside app/, else its first component;
// empty for a file at the top of the root.
std::string FolderOf(const std::string& path) {
  const std::size_t slash = path.find('/');
  if (slash == std::string::npos) return "";
  const std::string top = path.substr(0, slash);
  if (top != "app") return top;
  const std::size_t second = path.find('/', slash + 1);
  return second == std::string::npos ? "app" : path.substr(0, second);
}

// What each folder may include from the project and from outside.
struct Rule {
  std::set<std::string> project;  // project folders it may include
  bool mujoco = false;  // also sim/scene_model.h, sim/local_geoms.h and sim/local_physics.h, sim's internal headers with MuJoCo types
  bool yaml = false;
  bool gl = false;
  bool files_and_printing = true;  // <fstream>, <iostream>
};

// The folders outside app/ that app/'s folders may use.
const std::set<std::string> kBelowApp = {"common", "config",   "sim",     "slam",    "explorer",
                                         "eval",   "rundir",   "realdata", "renders"};

std::set<std::string> With(std::set<std::string> folders, const std::set<std::string>& more) {
  folders.insert(more.begin(), more.end());
  return folders;
}

// app/'s folders in one direction: cli -> batch -> jobs -> engine. The engine
// (the closed loop and its parts) includes no other app folder and opens no
// files; the jobs (one driver per subcommand) use the engine; batch work
// (sweeps, campaigns, the process pool, Slurm) runs jobs; only the command
// line sees them all, and nothing includes it.
Rule RuleFor(const std::string& folder) {
  if (folder == "common") return {{"common"}, false, false, false, false};
  if (folder == "slam") return {{"common", "slam"}, false, false, false, false};
  if (folder == "explorer") return {{"common", "explorer"}, false, false, false, false};
  // Filters written against slam/filter.h: what slam/ may use, and slam/.
  if (folder == "examples") return {{"common", "slam", "examples"}, false, false, false, false};
  if (folder == "eval") return {{"common", "eval"}, false, false, false, false};
  // The run directory's format: common and files. eval/map_types.h is the
  // map feature the map CSVs hold, until one map feature lives in common/.
  if (folder == "rundir") return {{"common", "rundir"}, false, false, false, true};
  // Real logs: read files, know common's poses; not the run directory.
  if (folder == "realdata") return {{"common", "realdata"}, false, false, false, true};
  if (folder == "config") return {{"common", "config"}, false, true, false, true};
  if (folder == "sim") return {{"common", "sim"}, true, false, false, true};
  if (folder == "renders") return {kBelowApp, true, false, true, true};
  if (folder == "app/engine") return {With(kBelowApp, {"app/engine"}), false, false, false, false};
  if (folder == "app/jobs") return {With(kBelowApp, {"app/engine", "app/jobs"}), false, false, false, true};
  if (folder == "app/batch") {
    return {With(kBelowApp, {"app/engine", "app/jobs", "app/batch"}), false, false, false, true};
  }
  // The fuzz targets read inputs as the program does: config, rundir, real
  // logs, sim's world checks and grid, and app's RunConfig, import and
  // campaigns; no MuJoCo, YAML or GL of their own.
  if (folder == "fuzz") {
    return {{"common", "config", "rundir", "realdata", "sim", "app/engine", "app/jobs", "app/batch",
             "fuzz"},
            false, false, false, true};
  }
  // The Python extension: the closed loop and the jobs it runs, as the
  // command line does, but not the command line or batch work.
  if (folder == "python") {
    return {With(kBelowApp, {"app/engine", "app/jobs", "python"}), false, false, false, true};
  }
  return {With(kBelowApp, {"app/engine", "app/jobs", "app/batch", "app/cli"}), false, false, false,
          true};  // app/cli
}

// The project headers `text` includes.
std::vector<std::string> ProjectIncludes(const std::string& text) {
  std::vector<std::string> found;
  static const std::regex kInclude(R"re(^\s*#\s*include\s*"([^"]+)")re");
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    std::smatch match;
    if (std::regex_search(line, match, kInclude) && kCodeFolders.count(FolderOf(match[1])) > 0) {
      found.push_back(match[1]);
    }
  }
  return found;
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
    const std::string folder = FolderOf(header);
    if ((kCodeFolders.count(folder) > 0 || folder == "app") && rule.project.count(folder) == 0) {
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
  EXPECT_TRUE(Violations("#include \"slam/ekf_slam.h\"\n", RuleFor("app/cli")).empty());
  // MuJoCo's types reach app/ neither directly nor through sim's internal
  // header; renders/ may use both.
  const std::string internal = "#include \"sim/scene_model.h\"\n#include \"sim/scene.h\"\n";
  EXPECT_EQ(Violations(internal, RuleFor("app/cli")).size(), 1u);
  EXPECT_EQ(Violations("#include \"sim/local_geoms.h\"\n", RuleFor("app/jobs")).size(), 1u);
  EXPECT_EQ(Violations("#include \"sim/local_physics.h\"\n", RuleFor("app/engine")).size(), 1u);
  EXPECT_TRUE(Violations(internal, RuleFor("renders")).empty());
  // rundir/ may write files but knows nothing of MuJoCo, YAML, the filters
  // or the program.
  EXPECT_EQ(Violations(text, RuleFor("rundir")).size(), 4u);
  EXPECT_EQ(Violations("#include \"app/jobs/run.h\"\n#include \"slam/ekf_slam.h\"\n",
                       RuleFor("rundir")).size(),
            2u);
  // app/'s folders in one direction, cli -> batch -> jobs -> engine; nothing
  // includes the command line, and every app header is in one of them.
  const std::string app =
      "#include \"app/cli/x.h\"\n#include \"app/batch/sweep.h\"\n#include \"app/jobs/run.h\"\n"
      "#include \"app/engine/closed_loop.h\"\n#include \"app/git_commit.h\"\n";
  EXPECT_EQ(Violations(app, RuleFor("app/engine")).size(), 4u);
  EXPECT_EQ(Violations(app, RuleFor("app/jobs")).size(), 3u);
  EXPECT_EQ(Violations(app, RuleFor("app/batch")).size(), 2u);
  EXPECT_EQ(Violations(app, RuleFor("app/cli")).size(), 1u);
  EXPECT_EQ(Violations(app, RuleFor("fuzz")).size(), 2u);
  EXPECT_EQ(Violations(app, RuleFor("renders")).size(), 5u);
  // A filter of examples/ is written against slam/ alone: no engine, no files.
  EXPECT_EQ(Violations(app + "#include <fstream>\n#include \"slam/filter.h\"\n",
                       RuleFor("examples")).size(),
            6u);
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
  // app/ holds its code in its folders only.
  for (const auto& entry : fs::directory_iterator(root / "app")) {
    const std::string ext = entry.path().extension().string();
    EXPECT_TRUE(ext != ".h" && ext != ".cc") << entry.path() << ": not in one of app/'s folders";
  }
}

// A cycle of the graph `edges` (folder -> the folders it includes), as the
// folders along it, first repeated at the end; empty when there is none.
std::vector<std::string> FindCycle(const std::map<std::string, std::set<std::string>>& edges) {
  // Depth-first search: a folder met again while still on the path closes a cycle.
  std::map<std::string, int> state;  // 0 unseen, 1 on the path, 2 done
  std::vector<std::string> path;
  std::vector<std::string> cycle;
  std::function<bool(const std::string&)> visit = [&](const std::string& folder) {
    state[folder] = 1;
    path.push_back(folder);
    const auto it = edges.find(folder);
    if (it != edges.end()) {
      for (const std::string& next : it->second) {
        if (state[next] == 1) {
          cycle.assign(std::find(path.begin(), path.end(), next), path.end());
          cycle.push_back(next);
          return true;
        }
        if (state[next] == 0 && visit(next)) return true;
      }
    }
    path.pop_back();
    state[folder] = 2;
    return false;
  };
  for (const auto& [folder, included] : edges) {
    if (state[folder] == 0 && visit(folder)) return cycle;
  }
  return {};
}

TEST(LayeringTest, FindsACycle) {
  EXPECT_TRUE(FindCycle({{"a", {"b"}}, {"b", {"c"}}, {"a2", {"c"}}}).empty());
  EXPECT_EQ(FindCycle({{"a", {"b"}}, {"b", {"c"}}, {"c", {"b"}}}),
            (std::vector<std::string>{"b", "c", "b"}));
}

// No folder reaches itself through its includes: among the project's folders
// and app/'s, the includes form no cycle, whatever the rules above allow.
TEST(LayeringTest, NoIncludeCycleAmongFolders) {
  const fs::path root(MJSLAM_SOURCE_DIR);
  std::map<std::string, std::set<std::string>> edges;
  for (const std::string& folder : kCodeFolders) {
    if (!fs::exists(root / folder)) continue;
    for (const auto& entry : fs::recursive_directory_iterator(root / folder)) {
      const std::string ext = entry.path().extension().string();
      if (ext != ".h" && ext != ".cc") continue;
      std::ifstream in(entry.path());
      std::stringstream text;
      text << in.rdbuf();
      for (const std::string& header : ProjectIncludes(text.str())) {
        if (FolderOf(header) != folder) edges[folder].insert(FolderOf(header));
      }
    }
  }
  EXPECT_GT(edges.size(), 8u);
  const std::vector<std::string> cycle = FindCycle(edges);
  std::string text;
  for (const std::string& folder : cycle) text += folder + " ";
  EXPECT_TRUE(cycle.empty()) << "include cycle: " << text;
}

// The closed loop (app/engine/closed_loop.*) runs the simulator or a
// recording, the filters and the driver; it writes no files, prints nothing
// and knows nothing of rendering or YAML (its callers do).
TEST(LayeringTest, ClosedLoopWritesNoFilesAndDoesNotRender) {
  const Rule rule = {{"common", "sim", "slam", "explorer", "eval", "rundir", "app/engine"},
                     false, false, false, false};
  EXPECT_EQ(Violations("#include \"renders/image.h\"\n#include <fstream>\n", rule).size(), 2u);
  const fs::path root(MJSLAM_SOURCE_DIR);
  for (const char* file : {"app/engine/closed_loop.h", "app/engine/closed_loop.cc"}) {
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
