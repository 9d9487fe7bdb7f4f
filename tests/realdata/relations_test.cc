// The relation metric against a case computed by hand, the reader's errors,
// and the time-offset search.
#include "realdata/relations.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <gtest/gtest.h>

namespace mjslam::realdata {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string WriteFile(const std::string& name, const std::string& text) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "mjslam_relations_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

// Three poses; two relations whose errors are worked out by hand:
//   A (t 10 -> 20): X1 = (0, 0, 0), X2 = (1, 0, pi/2): delta = (1, 0, pi/2);
//     the relation says (1, 0.3, pi/2 - 0.1): errors 0.3 m and 0.1 rad.
//   B (t 20 -> 30): X2 = (1, 0, pi/2), X3 = (1, 2, pi/2): delta = (2, 0, 0)
//     in X2's frame (2 m ahead, along +y of the world); the relation says
//     (2.4, 0, 0.2): errors 0.4 m and 0.2 rad.
// Means 0.35 m and 0.15 rad; std (n - 1) of {0.3, 0.4} = 0.0707107 m and of
// {0.1, 0.2} rad; squares {0.09, 0.16}: mean 0.125 m^2.
TEST(RelationsTest, HandComputedCase) {
  const std::vector<TimedPose> trajectory = {
      {110.0, Pose2(0, 0, 0)}, {120.001, Pose2(1, 0, kPi / 2)}, {130.0, Pose2(1, 2, kPi / 2)}};
  const std::vector<Relation> relations = {
      {10.0, 20.0, Pose2(1, 0.3, kPi / 2 - 0.1), 1},
      {20.0, 30.0, Pose2(2.4, 0, 0.2), 2},
      {30.0, 45.0, Pose2(0, 0, 0), 3}};  // t = 45 has no pose: not matched
  RelationMatching matching;
  matching.time_offset_s = -100.0;  // the trajectory's clock is 100 s ahead
  matching.tolerance_s = 0.002;
  const RelationErrors e = ScoreRelations(relations, trajectory, matching);
  const double deg = 180.0 / kPi;
  EXPECT_EQ(e.num_relations, 3);
  EXPECT_EQ(e.num_matched, 2);
  EXPECT_NEAR(e.translation_mean_m, 0.35, 1e-12);
  EXPECT_NEAR(e.translation_std_m, std::sqrt(0.005), 1e-12);
  EXPECT_NEAR(e.rotation_mean_deg, 0.15 * deg, 1e-9);
  EXPECT_NEAR(e.rotation_std_deg, std::sqrt(0.005) * deg, 1e-9);
  EXPECT_NEAR(e.translation_sq_mean_m2, 0.125, 1e-12);
  EXPECT_NEAR(e.rotation_sq_mean_deg2, 0.025 * deg * deg, 1e-9);

  // Outside the tolerance the 120.001 s pose no longer matches: nothing does.
  matching.tolerance_s = 0.0005;
  EXPECT_EQ(ScoreRelations(relations, trajectory, matching).num_matched, 0);
}

TEST(RelationsTest, NearestPoseWithinTolerance) {
  const std::vector<TimedPose> trajectory = {{1.0, Pose2()}, {2.0, Pose2()}, {3.0, Pose2()}};
  EXPECT_EQ(NearestPose(trajectory, 2.004, 0.006), 1);
  EXPECT_EQ(NearestPose(trajectory, 2.6, 0.5), 2);
  EXPECT_EQ(NearestPose(trajectory, 2.5 + 0.1, 0.05), -1);
  EXPECT_EQ(NearestPose(trajectory, 0.0, 0.5), -1);
  EXPECT_EQ(NearestPose(trajectory, 3.4, 0.5), 2);
}

TEST(RelationsTest, ReadsAndRejectsBadLines) {
  const std::string good = WriteFile(
      "good.relations", "976052905.167303 976052911.885496 -0.056990 -0.128430 0 0 0 -1.682210\n\n"
                        "1.5 2.5 1 2 0 0 0 0.5\n");
  const std::vector<Relation> relations = ReadRelations(good);
  ASSERT_EQ(relations.size(), 2u);
  EXPECT_EQ(relations[0].t1_s, 976052905.167303);
  EXPECT_EQ(relations[0].delta.y, -0.128430);
  EXPECT_EQ(relations[0].delta.theta, -1.682210);  // the yaw, 8th number
  EXPECT_EQ(relations[1].line, 3);
  const std::string short_line = WriteFile("short.relations", "1 2 3 4 5 6 7 8\n1 2 3\n");
  try {
    ReadRelations(short_line);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(short_line + ":2: expected 8 numbers"), std::string::npos);
  }
  EXPECT_THROW(ReadRelations(WriteFile("word.relations", "1 2 3 4 5 6 7 x\n")),
               std::runtime_error);
  EXPECT_THROW(ReadRelations(WriteFile("empty.relations", "")), std::runtime_error);
}

// Scan times with a known clock offset: the search finds it, and every
// relation time falls on a scan.
TEST(RelationsTest, BestTimeOffsetFindsAKnownOffset) {
  std::vector<TimedPose> scans;
  for (int i = 0; i < 50; ++i) scans.push_back({0.37 * i + 0.01 * (i % 3), Pose2()});
  std::vector<Relation> relations;
  for (int i = 0; i + 5 < 50; i += 3) {
    relations.push_back({scans[i].t_s + 1000.25, scans[i + 5].t_s + 1000.25, Pose2(), i});
  }
  int matched = 0;
  const double offset = BestTimeOffset(relations, scans, 0.001, &matched);
  EXPECT_NEAR(offset, 1000.25, 0.001);
  EXPECT_EQ(matched, 2 * static_cast<int>(relations.size()));  // 30 distinct times
}

// Issue 32, item 2 and 4: a negative tolerance overflowed the heap (the
// window's start ran past its end); a search larger than its limit is
// refused before it allocates.
TEST(RelationsTest, BestTimeOffsetRefusesABadToleranceAndTooManyCandidates) {
  std::vector<TimedPose> scans;
  for (int i = 0; i < 50; ++i) scans.push_back({0.37 * i, Pose2()});
  const std::vector<Relation> relations = {{1.0, 2.0, Pose2(), 1}, {3.0, 4.0, Pose2(), 2}};
  for (double tolerance : {-1.0, 0.0, std::nan(""), HUGE_VAL}) {
    EXPECT_THROW(BestTimeOffset(relations, scans, tolerance, nullptr), std::invalid_argument)
        << tolerance;
  }
  EXPECT_THROW(BestTimeOffset(relations, scans, 0.006, nullptr, 199), std::length_error);
  // Times of 1e308 made the offset infinite (found by the fuzz target import).
  EXPECT_THROW(ReadRelations(WriteFile("huge.relations", "1e308 1.5e308 0 0 0 0 0 0\n")),
               std::runtime_error);
  EXPECT_NO_THROW(BestTimeOffset(relations, scans, 0.006, nullptr, 200));
}

}  // namespace
}  // namespace mjslam::realdata
