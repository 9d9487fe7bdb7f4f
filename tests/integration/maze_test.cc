// Regression of the maze map loss (docs/results.md, "The maze map loss"): in
// a maze of thin walls seen from both sides, a line observation of a wall's
// back face was matched to the feature of its front face, 0.15 m away, and
// pulled pose and map; the filters lost the map after about 660 s. A line
// now matches only line features seen from the same side
// (slam.ekf.gate_line_side). 150 s of the explorer in the 40 x 40 m maze
// (seed 1), then the recorded run replayed through the classical filter with
// every line association checked against the true walls
// (tests/support/association_audit.h): none may go to another line; the same
// recording replayed without the side gate gives such matches (so the check
// can fail).
#include <cstdio>

#include <gtest/gtest.h>

#include "tests/integration/run_helpers.h"
#include "tests/support/association_audit.h"

namespace mjslam::testing {
namespace {

TEST(MazeTest, NoLineMatchesAnotherFaceOfItsWall) {
  const std::string dir = FreshDir("maze");
  ASSERT_EQ(Shell(Program() + " run --quiet --no-render --no-evaluate --config " + DefaultConfig() +
                  " --world " + std::string(MJSLAM_SOURCE_DIR) +
                  "/tests/integration/maze_40x40.xml --duration 150 --seed 1 --out " + dir +
                  " 2> " + dir + ".log"),
            0)
      << ReadText(dir + ".log");
  for (const std::string filter : {"classical", "selective"}) {
    const AssociationAudit audit = AuditAssociations(dir, filter, {});
    const AssociationAudit without = AuditAssociations(dir, filter, {"slam.ekf.gate_line_side=false"});
    std::printf("%s: wrong line matches %d, duplicate lines %d; without the side gate %d, %d\n",
                filter.c_str(), audit.total_wrong_matches(), audit.total_duplicates(),
                without.total_wrong_matches(), without.total_duplicates());
    for (std::size_t i = 0; i < audit.events.size() && i < 10; ++i) {
      std::printf("  %s\n", audit.events[i].c_str());
    }
    EXPECT_EQ(audit.total_wrong_matches(), 0) << filter;
    EXPECT_GT(without.total_wrong_matches(), 0) << filter;
  }
}

}  // namespace
}  // namespace mjslam::testing
