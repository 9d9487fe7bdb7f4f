// config/ keeps yaml-cpp out of its headers: they are included by app/ and by
// the header-only archives, which must work on ConfigNode alone. (The other
// folders are covered by tests/layering_test.cc.)
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

// Whether a line is an #include of a yaml-cpp header.
bool IncludesYamlCpp(const std::string& line) {
  const std::size_t hash = line.find_first_not_of(" \t");
  if (hash == std::string::npos || line[hash] != '#') return false;
  const std::size_t include = line.find("include", hash);
  if (include == std::string::npos) return false;
  return line.find("yaml-cpp/", include) != std::string::npos;
}

// Files of config/ that include a yaml-cpp header.
std::vector<std::string> ConfigFilesIncludingYamlCpp() {
  std::vector<std::string> found;
  for (const fs::directory_entry& entry :
       fs::directory_iterator(fs::path(MJSLAM_SOURCE_DIR) / "config")) {
    std::ifstream in(entry.path());
    std::string line;
    while (std::getline(in, line)) {
      if (IncludesYamlCpp(line)) {
        found.push_back(entry.path().filename().string());
        break;
      }
    }
  }
  return found;
}

TEST(YamlIncludeTest, DetectsYamlCppIncludeLines) {
  EXPECT_TRUE(IncludesYamlCpp("#include <yaml-cpp/yaml.h>"));
  EXPECT_TRUE(IncludesYamlCpp("  #  include \"yaml-cpp/node/node.h\""));
  EXPECT_FALSE(IncludesYamlCpp("// #include <yaml-cpp/yaml.h>"));
  EXPECT_FALSE(IncludesYamlCpp("#include \"config/config.h\""));
}

TEST(YamlIncludeTest, OnlyConfigSourcesIncludeYamlCpp) {
  const std::vector<std::string> found = ConfigFilesIncludingYamlCpp();
  for (const std::string& name : found) {
    EXPECT_EQ(fs::path(name).extension(), ".cc") << "config/" << name << " includes yaml-cpp";
  }
  // The scan works: it finds the parser, which must include yaml-cpp.
  EXPECT_NE(std::find(found.begin(), found.end(), "yaml_parser.cc"), found.end());
}

}  // namespace
