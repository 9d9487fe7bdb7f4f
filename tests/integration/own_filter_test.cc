// Bring your own filter, end to end: examples/dead_reckoning.yaml runs the
// example's filter beside the paper's two in one closed loop; the run
// directory, its evaluation, a sweep and a campaign go by the filters' names.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "rundir/layout.h"
#include "rundir/rows.h"
#include "rundir/run_files.h"
#include "rundir/summary.h"
#include "tests/integration/run_helpers.h"

namespace mjslam::testing {
namespace {

std::string ExampleConfig() {
  return std::string(MJSLAM_SOURCE_DIR) + "/examples/dead_reckoning.yaml";
}

TEST(OwnFilterTest, ExampleFilterRunsBesideThePapersTwo) {
  const std::string dir = FreshDir("own_filter");
  ASSERT_EQ(Shell(Program() + " run --quiet --no-render --config " + ExampleConfig() +
                  " --duration 10 --seed 3 --out " + dir + " 2> " + dir + ".log"),
            0)
      << ReadText(dir + ".log");
  // trajectory.csv: every filter's columns by name, in the config's order.
  const std::vector<std::string> names = {"classical", "selective", "dead_reckoning"};
  const rundir::CsvTable trajectory = rundir::ReadCsv(rundir::PathIn(dir, rundir::kTrajectoryFile));
  EXPECT_EQ(trajectory.columns, rundir::TrajectoryColumns(names));
  const std::vector<rundir::TrajectoryRow> rows =
      rundir::ReadTrajectoryRows(rundir::PathIn(dir, rundir::kTrajectoryFile));
  ASSERT_EQ(rows.back().filters.size(), 3u);
  EXPECT_EQ(rows.back().filters[2].name, "dead_reckoning");
  EXPECT_EQ(rows.back().filters[2].num_features, 0);
  EXPECT_GT(rows.back().filters[2].P(0, 0), 0.0);
  // A map per filter (the dead-reckoning one empty), a summary per filter.
  for (const std::string& name : names) {
    EXPECT_TRUE(std::filesystem::exists(rundir::PathIn(dir, rundir::MapFile(name)))) << name;
  }
  nlohmann::json summary = rundir::ReadSummary(dir);
  EXPECT_EQ(summary["filters"].size(), 3u);
  EXPECT_EQ(summary["filters"]["dead_reckoning"]["num_features"], 0);

  // mjslam evaluate scores all three; the divergence compares the paper's two
  // (classical and selective, when a run has both).
  ASSERT_EQ(Shell(Program() + " evaluate " + dir + " --divergence-points 200 > " + dir +
                  ".eval.log 2>&1"),
            0)
      << ReadText(dir + ".eval.log");
  summary = rundir::ReadSummary(dir);
  for (const std::string& name : names) {
    EXPECT_TRUE(summary["filters"][name].contains("inside_2sigma")) << name;
    EXPECT_TRUE(summary["filters"][name].contains("map")) << name;
  }
  EXPECT_TRUE(summary["divergence"].contains("classical_selective")) << summary["divergence"];
  EXPECT_NE(ReadText(dir + ".eval.log").find("dead_reckoning"), std::string::npos);
}

// With one filter a run is evaluated without the divergence; the divergence
// command, which needs two, says which filters it got.
TEST(OwnFilterTest, DivergenceWithoutThePapersPairNamesTheFilters) {
  const std::string dir = FreshDir("own_filter_pair");
  ASSERT_EQ(Shell(Program() + " run --quiet --no-render --config " + ExampleConfig() +
                  " --duration 3 --seed 3 --out " + dir +
                  " --set 'slam.filters=[{name: dr, kind: dead_reckoning}]' --set "
                  "control.pose_source=dr 2> " + dir + ".log"),
            0)
      << ReadText(dir + ".log");
  // The run's own evaluation leaves the divergence out, and says why.
  EXPECT_FALSE(rundir::ReadSummary(dir).contains("divergence"));
  EXPECT_NE(ReadText(dir + ".log").find("note: no divergence in summary.json"), std::string::npos)
      << ReadText(dir + ".log");
  EXPECT_TRUE(rundir::ReadSummary(dir)["filters"]["dr"].contains("mean_nees"));
  EXPECT_NE(Shell(Program() + " divergence " + dir + " --points 100 --realisations 2 > " + dir +
                  ".div.log 2>&1"),
            0);
  EXPECT_NE(ReadText(dir + ".div.log")
                .find("trajectory.csv: the map divergence needs two filters whose maps have a "
                      "corner or a seen line (got dr (nothing to compare))"),
            std::string::npos)
      << ReadText(dir + ".div.log");
}

// A sweep and a campaign of named filters: nees.csv, summary.json and the
// campaign table have a column or entry per filter of the runs, the
// selection policies of examples/selection_policies.yaml paired on the same
// records.
TEST(OwnFilterTest, SweepAndCampaignGoByFilterName) {
  const std::string root = FreshDir("own_filter_sweep");
  const std::string config = std::string(MJSLAM_SOURCE_DIR) + "/examples/selection_policies.yaml";
  const std::string common = " --config " + config + " --runs 2 --jobs 2 --duration 4 --quiet" +
                             " --set control.driver=tour --set render.enabled=false";
  ASSERT_EQ(Shell(Program() + " sweep" + common + " --divergence-points 200 --out " + root +
                  "/sweep > " + root + "/sweep.txt 2> " + root + "/sweep.log"),
            0)
      << ReadText(root + "/sweep.log");
  const std::vector<std::string> names = {"classical", "criterion", "first", "random",
                                          "least_informative", "determinant"};
  const rundir::CsvTable nees = rundir::ReadCsv(root + "/sweep/nees.csv");
  EXPECT_EQ(nees.columns, rundir::NeesColumns(names));
  const nlohmann::json summary = rundir::ReadSummary(root + "/sweep");
  for (const std::string& name : names) {
    EXPECT_TRUE(summary["filters"][name].contains("verdict")) << name;
    EXPECT_NE(ReadText(root + "/sweep.txt").find(name + " "), std::string::npos) << name;
  }
  // The runs' divergence (no selective filter: classical and criterion, the
  // first two with a map) averaged under its labels.
  for (const char* label : {"classical_criterion", "criterion_classical", "classical_truth",
                            "criterion_truth"}) {
    EXPECT_TRUE(summary["divergence"]["runs_mean"][label].is_number()) << label << summary["divergence"];
  }
  // A campaign over MAX: its table has each filter's columns.
  ASSERT_EQ(Shell(Program() + " sweep" + common + " --vary slam.ekf.max_updates=1,3 --out " +
                  root + "/campaign > /dev/null 2> " + root + "/campaign.log"),
            0)
      << ReadText(root + "/campaign.log");
  const std::string csv = ReadText(root + "/campaign/campaign.csv");
  for (const std::string& name : names) {
    EXPECT_NE(csv.find("," + name + "_verdict"), std::string::npos) << name << "\n" << csv;
  }
}

}  // namespace
}  // namespace mjslam::testing
