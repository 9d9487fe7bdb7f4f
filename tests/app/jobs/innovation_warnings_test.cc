// The warning lines of `mjslam run` for filters its innovation check found
// inconsistent (app/jobs/run.h, InnovationWarnings): none for a consistent
// filter; the time, the key, and the first scan that copied mapped
// structure when there was one.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/jobs/run.h"
#include "rundir/summary.h"

namespace mjslam::app {
namespace {

TEST(InnovationWarningsTest, NamesTheFirstCopyingScanOfALostFilter) {
  rundir::RunSummary summary;
  rundir::RunSummary::Filter healthy;
  healthy.name = "classical";
  rundir::RunSummary::Filter lost;
  lost.name = "selective";
  lost.innovation_inconsistent_since_s = 551.5;
  lost.map_copied_at_s = 551.5;
  lost.copied_scans = 16;
  lost.copies = 71;
  summary.filters = {healthy, lost};
  const std::vector<std::string> lines = InnovationWarnings(summary);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("the selective filter is inconsistent with its own innovations from "
                          "t = 551.5 s"),
            std::string::npos)
      << lines[0];
  EXPECT_NE(lines[0].find("16 scans made new features of mapped structure, the first at t = 551.5 s"),
            std::string::npos)
      << lines[0];
  EXPECT_NE(lines[0].find("filters.selective.innovation_check"), std::string::npos) << lines[0];

  // Inconsistent by the near-miss test alone: no copy clause.
  summary.filters[1].map_copied_at_s.reset();
  summary.filters[1].copied_scans = 0;
  const std::vector<std::string> near_misses_only = InnovationWarnings(summary);
  ASSERT_EQ(near_misses_only.size(), 1u);
  EXPECT_EQ(near_misses_only[0].find("mapped structure"), std::string::npos) << near_misses_only[0];
}

}  // namespace
}  // namespace mjslam::app
