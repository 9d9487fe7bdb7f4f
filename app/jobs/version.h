#pragma once

#include <string>

namespace mjslam::app {

/// Version of mjslam and the git commit it was built from.
std::string MjslamVersion();
std::string MjslamGitCommit();

}  // namespace mjslam::app
