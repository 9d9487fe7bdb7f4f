// The grid of a campaign: cells, their names and overrides, the campaign
// file's errors, --vary's syntax, and the table across cells.
#include "app/batch/campaign.h"

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include "config/config_node.h"
#include "rundir/csv_writer.h"

namespace mjslam::app {
namespace {

namespace fs = std::filesystem;

std::string WriteCampaign(const std::string& name, const std::string& text) {
  const fs::path path = fs::temp_directory_path() / ("mjslam_campaign_test_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path.string();
}

TEST(CampaignTest, CellsAreWorldsTimesEachAxisLastAxisFastest) {
  CampaignParams campaign;
  campaign.worlds = {"/w/room.xml", "/w/office.xml"};
  campaign.axes = {{"slam.ekf.max_updates", {"1", "2"}}, {"laser.range_noise_std_m", {"0.01"}}};
  const std::vector<CampaignCell> cells = CampaignCells(campaign);
  ASSERT_EQ(cells.size(), 4u);
  EXPECT_EQ(cells[0].name, "room__slam.ekf.max_updates=1__laser.range_noise_std_m=0.01");
  EXPECT_EQ(cells[1].name, "room__slam.ekf.max_updates=2__laser.range_noise_std_m=0.01");
  EXPECT_EQ(cells[2].name, "office__slam.ekf.max_updates=1__laser.range_noise_std_m=0.01");
  EXPECT_EQ(cells[3].overrides,
            (std::vector<std::string>{"run.world=/w/office.xml", "slam.ekf.max_updates=2",
                                      "laser.range_noise_std_m=0.01"}));
  EXPECT_EQ(cells[3].labels.front(), (std::pair<std::string, std::string>{"world", "office"}));
}

TEST(CampaignTest, ConditionsAreAnAxisOfNamedOverrideSets) {
  CampaignParams campaign;
  campaign.worlds = {"/w/room.xml"};
  campaign.axes = {{"slam.ekf.max_updates", {"1", "2"}}};
  campaign.conditions = {{"nominal", {}},
                         {"bias+15mm", {"laser.range_bias_m=0.015", "laser.range_bias_std_m=0"}}};
  EXPECT_EQ(CampaignCellCount(campaign, 100), 4u);
  const std::vector<CampaignCell> cells = CampaignCells(campaign);
  ASSERT_EQ(cells.size(), 4u);
  EXPECT_EQ(cells[0].name, "room__slam.ekf.max_updates=1__nominal");
  EXPECT_EQ(cells[1].name, "room__slam.ekf.max_updates=1__bias+15mm");
  EXPECT_EQ(cells[1].overrides,
            (std::vector<std::string>{"run.world=/w/room.xml", "slam.ekf.max_updates=1",
                                      "laser.range_bias_m=0.015", "laser.range_bias_std_m=0"}));
  EXPECT_EQ(cells[3].labels.back(),
            (std::pair<std::string, std::string>{"condition", "bias+15mm"}));
  campaign.conditions.push_back({"nominal", {"a.b=1"}});
  EXPECT_THROW(CampaignCells(campaign), std::runtime_error);  // two folders named nominal
}

TEST(CampaignTest, ConditionsInAFileTakeWorldsRelativeToItAndBadOnesAreNamed) {
  const std::string path = WriteCampaign(
      "conditions.yaml",
      "conditions:\n  - {name: nominal}\n  - {name: pillars, set: [run.world=w/pillars.xml, "
      "sim.drive_disturbance_std_fraction=0.02]}\n");
  const CampaignParams campaign = LoadCampaign(path);
  ASSERT_EQ(campaign.conditions.size(), 2u);
  EXPECT_TRUE(campaign.conditions[0].set.empty());
  EXPECT_EQ(campaign.conditions[1].set[0],
            "run.world=" + (fs::path(path).parent_path() / "w/pillars.xml").string());
  EXPECT_EQ(campaign.conditions[1].set[1], "sim.drive_disturbance_std_fraction=0.02");
  for (const char* bad : {"conditions:\n  - {name: 'a b'}\n",
                          "conditions:\n  - {name: ok, set: [no_equals]}\n"}) {
    try {
      LoadCampaign(WriteCampaign("bad_condition.yaml", bad));
      ADD_FAILURE() << bad;
    } catch (const config::ConfigError& error) {
      EXPECT_NE(std::string(error.what()).find("conditions[0]"), std::string::npos)
          << error.what();
    }
  }
}

TEST(CampaignTest, WithoutWorldsTheConfigsWorldIsKept) {
  CampaignParams campaign;
  campaign.axes = {{"slam.ekf.max_updates", {"1", "3"}}};
  const std::vector<CampaignCell> cells = CampaignCells(campaign);
  ASSERT_EQ(cells.size(), 2u);
  EXPECT_EQ(cells[1].name, "slam.ekf.max_updates=3");
  EXPECT_EQ(cells[1].overrides, std::vector<std::string>{"slam.ekf.max_updates=3"});
}

TEST(CampaignTest, TwoCellsInOneFolderAreRefused) {
  CampaignParams campaign;
  campaign.worlds = {"/a/room.xml", "/b/room.xml"};
  EXPECT_THROW(CampaignCells(campaign), std::runtime_error);
}

TEST(CampaignTest, VaryOptionsSplitAtCommasAndBadOnesAreNamed) {
  const CampaignParams campaign =
      CampaignFromOptions({"worlds/room.xml"}, {"slam.ekf.max_updates=1,2,3", "a.b=x"});
  ASSERT_EQ(campaign.axes.size(), 2u);
  EXPECT_EQ(campaign.axes[0].values, (std::vector<std::string>{"1", "2", "3"}));
  EXPECT_TRUE(fs::path(campaign.worlds[0]).is_absolute());
  for (const char* bad : {"slam.ekf.max_updates", "=1,2", "key=", "key=1,,2"}) {
    try {
      CampaignFromOptions({}, {bad});
      ADD_FAILURE() << bad;
    } catch (const std::runtime_error& error) {
      EXPECT_NE(std::string(error.what()).find(bad), std::string::npos) << error.what();
    }
  }
}

TEST(CampaignTest, FileIsReadWithWorldsRelativeToItsFolder) {
  const std::string path = WriteCampaign("good.yaml",
                                         "runs: 40\nworlds: [w/room.xml]\naxes:\n"
                                         "  - key: slam.ekf.max_updates\n    values: [1, 2]\n");
  const CampaignParams campaign = LoadCampaign(path);
  EXPECT_EQ(campaign.runs, 40);
  EXPECT_EQ(campaign.worlds[0], (fs::path(path).parent_path() / "w/room.xml").string());
  EXPECT_EQ(campaign.axes[0].values, (std::vector<std::string>{"1", "2"}));
}

TEST(CampaignTest, FileErrorsNameTheFileLineAndKey) {
  const std::string path = WriteCampaign(
      "bad.yaml", "runs: 40\nseeds: 3\naxes:\n  - key: slam.ekf.max_updates\n    values: []\n");
  try {
    LoadCampaign(path);
    FAIL() << "no error";
  } catch (const config::ConfigError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(path + ":2"), std::string::npos) << message;  // unknown key seeds
    EXPECT_NE(message.find("seeds"), std::string::npos) << message;
    EXPECT_NE(message.find("axes[0].values"), std::string::npos) << message;
  }
}

TEST(CampaignTest, EveryShippedCampaignLoadsAndItsWorldsExist) {
  int count = 0;
  for (const auto& entry :
       fs::directory_iterator(fs::path(MJSLAM_SOURCE_DIR) / "configs" / "campaigns")) {
    SCOPED_TRACE(entry.path().string());
    const CampaignParams campaign = LoadCampaign(entry.path().string());
    for (const std::string& world : campaign.worlds) EXPECT_TRUE(fs::exists(world)) << world;
    EXPECT_GE(CampaignCells(campaign).size(), 2u);
    ++count;
  }
  EXPECT_GE(count, 1);
}

TEST(CampaignTest, TableHasOneRowPerCellWithItsLabelsAndVerdicts) {
  CampaignParams campaign;
  campaign.worlds = {"/w/room.xml"};
  campaign.axes = {{"slam.ekf.max_updates", {"1", "2"}}};
  const std::vector<CampaignCell> cells = CampaignCells(campaign);
  std::vector<nlohmann::json> summaries(2);
  summaries[0]["sweep"]["completed_runs"] = 40;
  summaries[0]["filters"]["classical"] = {{"fraction_inside", 0.5}, {"verdict", "overconfident"}};
  summaries[1]["sweep"]["completed_runs"] = 40;
  summaries[1]["filters"]["selective"] = {{"mean_anees", 3.0}, {"verdict", "consistent"}};
  const std::string csv = CampaignTableCsv(cells, summaries);
  const std::string header = csv.substr(0, csv.find('\n'));
  EXPECT_EQ(header.rfind("cell,world,slam.ekf.max_updates,runs,classical_fraction_inside,", 0), 0u)
      << header;
  EXPECT_NE(csv.find("\nroom__slam.ekf.max_updates=1,room,1,40,0.5,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",overconfident,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",3,"), std::string::npos) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);
  const std::string text = CampaignTableText(cells, summaries);
  EXPECT_NE(text.find("room__slam.ekf.max_updates=2"), std::string::npos) << text;
  EXPECT_NE(text.find("consistent"), std::string::npos) << text;
}

// Issue 32, item 6: a label with a comma or a quote shifted the columns of
// campaign.csv; a world named `...xml` made its cell folder `..`; three
// spellings of one value made three identical cells.
TEST(CampaignTest, LabelsAreQuotedFoldersStayInsideAndValuesAreDistinct) {
  CampaignParams campaign;
  campaign.worlds = {"/w/a,b\"c.xml", "/w/...xml"};
  const std::vector<CampaignCell> cells = CampaignCells(campaign);
  ASSERT_EQ(cells.size(), 2u);
  EXPECT_EQ(cells[1].name, "_.");  // the stem "..", no longer the folder above
  EXPECT_EQ(cells[0].name, "a_b_c");
  std::vector<nlohmann::json> summaries(2);
  for (nlohmann::json& summary : summaries) summary["sweep"]["completed_runs"] = 0;
  const std::string csv = CampaignTableCsv(cells, summaries);
  EXPECT_NE(csv.find("\na_b_c,\"a,b\"\"c\",0,"), std::string::npos) << csv;
  EXPECT_EQ(rundir::CsvField("plain"), "plain");
  EXPECT_EQ(rundir::CsvField("a\nb"), "\"a\nb\"");

  campaign.worlds.clear();
  campaign.axes = {{"slam.ekf.max_updates", {"10", "10.0", "1e1"}}};
  EXPECT_THROW(CampaignCells(campaign), std::runtime_error);
  campaign.axes = {{"control.pose_source", {"classical", "classical"}}};
  EXPECT_THROW(CampaignCells(campaign), std::runtime_error);
  // The count, without making the cells.
  campaign.axes.assign(9, {"run.seed", {"1", "2", "3", "4", "5", "6", "7", "8", "9", "10"}});
  EXPECT_EQ(CampaignCellCount(campaign, 1000), 1001u);
  campaign.axes.resize(2);
  EXPECT_EQ(CampaignCellCount(campaign, 1000), 100u);
}

}  // namespace
}  // namespace mjslam::app
