// The map CSV files: a map written and read back unchanged.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "rundir/map_csv.h"

namespace mjslam::rundir {
namespace {

TEST(MapCsvTest, MapRoundTripsBitForBit) {
  MapFeature line;
  line.id = 3;
  line.type = MapFeature::Type::kLine;
  line.params = {2.0 / 3.0, -0.1};
  line.covariance << 1e-6, 1e-7, 1e-7, 3e-8;
  line.has_segment = true;
  line.p_WA = {0.1, 1.0 / 7.0};
  line.p_WB = {-4.0, 0.7};
  MapFeature corner;
  corner.id = 8;
  corner.type = MapFeature::Type::kCorner;
  corner.params = {1.25, -3.5};
  corner.covariance << 4e-4, -1e-5, -1e-5, 9e-4;

  const std::string path =
      (std::filesystem::temp_directory_path() / "mjslam_map_csv_test.csv").string();
  WriteMapCsv(path, {line, corner});
  const FeatureMap map = ReadMapCsv(path);
  ASSERT_EQ(map.size(), 2u);
  EXPECT_EQ(map[0].id, 3);
  EXPECT_EQ(map[0].type, MapFeature::Type::kLine);
  EXPECT_EQ(map[0].params, line.params);
  EXPECT_EQ(map[0].covariance, line.covariance);
  EXPECT_TRUE(map[0].has_segment);
  EXPECT_EQ(map[0].p_WA, line.p_WA);
  EXPECT_EQ(map[0].p_WB, line.p_WB);
  EXPECT_EQ(map[1].id, 8);
  EXPECT_EQ(map[1].type, MapFeature::Type::kCorner);
  EXPECT_EQ(map[1].params, corner.params);
  EXPECT_EQ(map[1].covariance, corner.covariance);
  EXPECT_FALSE(map[1].has_segment);
  std::filesystem::remove(path);
}

TEST(MapCsvTest, UnknownTypeIsAnErrorNamingFileAndLine) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "mjslam_map_csv_bad.csv").string();
  std::ofstream(path) << "id,type,p0,p1,c00,c01,c11,ax,ay,bx,by\n0,wall,1,0,1,0,1,,,,\n";
  try {
    ReadMapCsv(path);
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(path + ":2: type"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("wall"), std::string::npos) << error.what();
  }
  std::filesystem::remove(path);
}

// Rows no filter or ground truth can write are refused with the file, the
// line and the values (the divergence assumed a positive definite covariance
// and aborted on the first that was not).
TEST(MapCsvTest, ImpossibleFeaturesAreErrorsNamingFileLineAndValues) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "mjslam_map_csv_impossible.csv").string();
  struct Case {
    std::string row;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"0,corner,1,2,1e-4,2e-4,1e-4,,,,", ":2: c00, c01, c11: expected a positive semidefinite covariance (got p0..c11 = 1, 2, 1e-04, 2e-04, 1e-04)"},
      {"0,corner,1,2,-1e-4,0,1e-4,,,,", ":2: c00, c01, c11: expected a positive semidefinite"},
      {"0,line,-1,0,1e-4,0,1e-4,,,,", ":2: p0: expected a line distance rho"},
      {"0,line,1,4,1e-4,0,1e-4,,,,", ":2: p1: expected a line angle alpha"},
      {"0,corner,1e308,2,0,0,0,,,,", ":2: p0, p1: expected a corner within 1e6 m"},
      {"0,line,1,0,0,0,0,1,1e300,1,2", ":2: ax, ay, bx, by: expected a segment within 1e6 m"},
      // Ids that no int holds (casting them is undefined behaviour: the
      // sanitizer build reports a cast made before the check).
      {"nan,corner,1,2,0,0,0,,,,", ":2: id: expected a whole number in [0, 1e9] (got nan)"},
      {"1e308,corner,1,2,0,0,0,,,,", ":2: id: expected a whole number in [0, 1e9]"},
      {"2147483648,corner,1,2,0,0,0,,,,", ":2: id: expected a whole number in [0, 1e9]"},
      {"1.5,corner,1,2,0,0,0,,,,", ":2: id: expected a whole number in [0, 1e9]"},
  };
  for (const Case& c : cases) {
    std::ofstream(path) << "id,type,p0,p1,c00,c01,c11,ax,ay,bx,by\n" << c.row << "\n";
    try {
      ReadMapCsv(path);
      ADD_FAILURE() << "no error for " << c.row;
    } catch (const std::runtime_error& error) {
      EXPECT_NE(std::string(error.what()).find(path + c.expected), std::string::npos) << error.what();
    }
  }
  // The ground truth's zero covariance and a covariance whose determinant
  // rounds to zero are a map's.
  std::ofstream(path) << "id,type,p0,p1,c00,c01,c11,ax,ay,bx,by\n0,corner,1,2,0,0,0,,,,\n"
                      << "1,corner,1,2,1e-4,1e-4,1e-4,,,,\n";
  EXPECT_EQ(ReadMapCsv(path).size(), 2u);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace mjslam::rundir
