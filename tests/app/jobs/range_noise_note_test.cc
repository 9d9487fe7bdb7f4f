// The note `mjslam run` prints when the filters' model of the range noise
// is not the simulated laser's.
#include <gtest/gtest.h>

#include "app/jobs/run.h"

namespace mjslam::app {
namespace {

TEST(RangeNoiseNoteTest, NoneWhenTheModelMatchesTheSensor) {
  RunConfig config;
  EXPECT_EQ(config.laser.range_noise_std_m, config.slam.features.range_noise_std_m);
  EXPECT_FALSE(RangeNoiseNote(config).has_value());
}

TEST(RangeNoiseNoteTest, NamesBothKeysAndValuesWhenTheyDiffer) {
  RunConfig config;
  config.laser.range_noise_std_m = 0.0;  // --set laser.range_noise_std_m=0
  const std::optional<std::string> note = RangeNoiseNote(config);
  ASSERT_TRUE(note.has_value());
  EXPECT_NE(note->find("slam.features.range_noise_std_m"), std::string::npos) << *note;
  EXPECT_NE(note->find("laser.range_noise_std_m"), std::string::npos) << *note;
  EXPECT_NE(note->find("0.005 m (slam"), std::string::npos) << *note;
  EXPECT_NE(note->find(" 0 m (laser"), std::string::npos) << *note;
  EXPECT_EQ(note->find('\n'), std::string::npos);  // one line
}

}  // namespace
}  // namespace mjslam::app
