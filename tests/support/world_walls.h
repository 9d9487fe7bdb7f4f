#pragma once

// Test-only reader of the shipped worlds' obstacles for the kinematic
// simulator: the `box` and `cylinder` geoms of a worlds/*.xml file (as the
// generator writes them: one element per line, yaw from `euler="0 0 deg"`)
// become wall segments (a cylinder becomes a 24-sided polygon), and the
// `start` site the start pose. Not an MJCF parser: enough for the files of
// sim/tools/generate_worlds.py, and it fails loudly on anything else.

#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/angles.h"
#include "common/pose2.h"
#include "tests/support/walls.h"

namespace mjslam::testing {

struct WorldWalls {
  std::vector<Wall> walls;
  Pose2 X_WR_start;
  bool has_start = false;
};

inline std::vector<double> Numbers(const std::string& text) {
  std::vector<double> values;
  std::istringstream in(text);
  double v;
  while (in >> v) values.push_back(v);
  return values;
}

inline std::string Attribute(const std::string& line, const std::string& name) {
  const std::regex pattern("\\s" + name + "=\"([^\"]*)\"");
  std::smatch match;
  return std::regex_search(line, match, pattern) ? match[1].str() : std::string();
}

inline WorldWalls ReadWorldWalls(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error("cannot open " + path);
  WorldWalls world;
  std::string line;
  while (std::getline(file, line)) {
    const bool geom = line.find("<geom") != std::string::npos;
    const bool start = line.find("<site name=\"start\"") != std::string::npos;
    if (!geom && !start) continue;
    const std::vector<double> pos = Numbers(Attribute(line, "pos"));
    const std::vector<double> euler = Numbers(Attribute(line, "euler"));
    const double yaw = euler.size() == 3 ? DegToRad(euler[2]) : 0.0;
    if (start) {
      world.X_WR_start = Pose2(pos.at(0), pos.at(1), yaw);
      world.has_start = true;
      continue;
    }
    const std::string type = Attribute(line, "type");
    const std::vector<double> size = Numbers(Attribute(line, "size"));
    if (type == "plane") continue;
    if (!Attribute(line, "quat").empty() || !Attribute(line, "axisangle").empty()) {
      throw std::runtime_error("unsupported orientation in " + path + ": " + line);
    }
    std::vector<Eigen::Vector2d> corners;
    if (type == "box") {
      const Pose2 X_WB(pos.at(0), pos.at(1), yaw);
      for (const auto& c : {Eigen::Vector2d(1, 1), Eigen::Vector2d(-1, 1),
                            Eigen::Vector2d(-1, -1), Eigen::Vector2d(1, -1)}) {
        corners.push_back(X_WB * Eigen::Vector2d(c.x() * size.at(0), c.y() * size.at(1)));
      }
    } else if (type == "cylinder") {
      for (int k = 0; k < 24; ++k) {
        const double th = 2.0 * kPi * k / 24;
        // Circumscribed polygon: never smaller than the cylinder.
        const double r = size.at(0) / std::cos(kPi / 24);
        corners.emplace_back(pos.at(0) + r * std::cos(th), pos.at(1) + r * std::sin(th));
      }
    } else {
      throw std::runtime_error("unsupported geom type '" + type + "' in " + path);
    }
    for (size_t k = 0; k < corners.size(); ++k) {
      world.walls.push_back({corners[k], corners[(k + 1) % corners.size()]});
    }
  }
  return world;
}

}  // namespace mjslam::testing
