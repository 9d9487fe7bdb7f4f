#include "app/jobs/version.h"

#include "app/jobs/git_commit.h"

namespace mjslam::app {

std::string MjslamVersion() { return MJSLAM_VERSION; }
std::string MjslamGitCommit() { return MJSLAM_GIT_COMMIT; }

}  // namespace mjslam::app
