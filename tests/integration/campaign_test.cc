// `mjslam sweep` over a campaign grid on the local backend: each cell is the
// sweep of its config (the same files as a plain sweep with the cell's --set
// options), the table has one row per cell, and `--aggregate DIR` rebuilds it.
#include <algorithm>
#include <filesystem>

#include <gtest/gtest.h>

#include "tests/integration/run_helpers.h"

namespace mjslam::testing {
namespace {

namespace fs = std::filesystem;

// Options every sweep of this test shares: 2 runs of 4 s of the room's tour.
std::string Common() {
  return " --config " + DefaultConfig() + " --runs 2 --jobs 2 --duration 4 --quiet" +
         " --set control.driver=tour --set render.enabled=false";
}

TEST(CampaignSweepTest, EachCellIsThePlainSweepOfItsConfigAndTheTableHasEveryCell) {
  const std::string root = FreshDir("campaign");
  const std::string room = std::string(MJSLAM_SOURCE_DIR) + "/worlds/room.xml";
  const std::string campaign = root + "/campaign";
  ASSERT_EQ(Shell(Program() + " sweep" + Common() + " --world " + room +
                  " --vary slam.ekf.max_updates=1,2 --out " + campaign + " > " + root +
                  "/table.txt 2> " + root + "/campaign.log"),
            0)
      << ReadText(root + "/campaign.log");
  const std::string cell = campaign + "/cells/room__slam.ekf.max_updates=1";
  ASSERT_TRUE(fs::exists(cell + "/runs/run_001/summary.json"));
  ASSERT_TRUE(fs::exists(campaign + "/cells/room__slam.ekf.max_updates=2/nees.csv"));

  // The same cell as a plain sweep: the same NEES table and run files.
  const std::string plain = root + "/plain";
  ASSERT_EQ(Shell(Program() + " sweep" + Common() + " --set run.world=" + room +
                  " --set slam.ekf.max_updates=1 --out " + plain + " > /dev/null 2> " + root +
                  "/plain.log"),
            0)
      << ReadText(root + "/plain.log");
  EXPECT_EQ(ReadText(cell + "/config.yaml"), ReadText(plain + "/config.yaml"));
  EXPECT_EQ(ReadText(cell + "/nees.csv"), ReadText(plain + "/nees.csv"));
  EXPECT_EQ(ReadText(cell + "/runs/run_001/scans.csv"), ReadText(plain + "/runs/run_001/scans.csv"));

  // The table: a header and one row per cell, printed and in campaign.csv.
  const std::string csv = ReadText(campaign + "/campaign.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3) << csv;
  EXPECT_NE(csv.find("\nroom__slam.ekf.max_updates=2,room,2,2,"), std::string::npos) << csv;
  EXPECT_NE(ReadText(root + "/table.txt").find("room__slam.ekf.max_updates=2"), std::string::npos);

  // --aggregate DIR rebuilds the same table from the directory alone.
  fs::remove(campaign + "/campaign.csv");
  ASSERT_EQ(Shell(Program() + " sweep --aggregate " + campaign + " > /dev/null 2> " + root +
                  "/aggregate.log"),
            0)
      << ReadText(root + "/aggregate.log");
  EXPECT_EQ(ReadText(campaign + "/campaign.csv"), csv);
}

TEST(CampaignSweepTest, AggregateListsTheRunsThatAreMissing) {
  const std::string root = FreshDir("campaign_missing");
  const std::string dir = root + "/sweep";
  ASSERT_EQ(Shell(Program() + " sweep" + Common() + " --out " + dir + " > /dev/null 2> " + root +
                  "/sweep.log"),
            0)
      << ReadText(root + "/sweep.log");
  fs::remove_all(dir + "/runs/run_001");
  EXPECT_EQ(Shell(Program() + " sweep --aggregate " + dir + " > /dev/null 2> " + root +
                  "/aggregate.log"),
            1);
  const std::string log = ReadText(root + "/aggregate.log");
  EXPECT_NE(log.find("1 of 2 runs failed"), std::string::npos) << log;
  EXPECT_NE(log.find(dir + "/runs/run_001: not completed"), std::string::npos) << log;
}

}  // namespace
}  // namespace mjslam::testing
