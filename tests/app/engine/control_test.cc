// The paper's command period and the processing-time sources.
#include <gtest/gtest.h>

#include "app/engine/control.h"

namespace mjslam::app {
namespace {

TEST(ControlTest, CommandPeriodIsTheProcessingRoundedUpToWholeSteps) {
  EXPECT_EQ(CommandPeriodSteps(0.0, 0.1), 1);    // at least one step
  EXPECT_EQ(CommandPeriodSteps(0.05, 0.1), 1);
  EXPECT_EQ(CommandPeriodSteps(0.1, 0.1), 1);    // exactly one period
  EXPECT_EQ(CommandPeriodSteps(0.2, 0.1), 2);    // 0.2 / 0.1 rounds to 2, not 3
  EXPECT_EQ(CommandPeriodSteps(0.15, 0.1), 2);   // the paper's example: 0.15 s -> 0.2 s
  EXPECT_EQ(CommandPeriodSteps(0.61, 0.1), 7);   // 0.7 s
}

TEST(ControlTest, CostModelGrowsWithUpdatesAndTheSquaredStateSize) {
  ControlParams params;
  params.model_base_s = 0.1;
  params.model_s_per_update_per_n2 = 1e-6;
  slam::StepReport report;
  report.num_features = 50;  // n = 103
  report.num_updated = 10;
  EXPECT_DOUBLE_EQ(ProcessingSeconds(params, report, true, 12345.0), 0.1 + 1e-6 * 10 * 103 * 103);
  report.num_updated = 2;
  EXPECT_DOUBLE_EQ(ProcessingSeconds(params, report, true, 12345.0), 0.1 + 1e-6 * 2 * 103 * 103);
  // A step without a scan is a prediction only.
  EXPECT_EQ(ProcessingSeconds(params, report, false, 12345.0), 0.0);
}

TEST(ControlTest, MeasuredTimeIsScaled) {
  ControlParams params;
  params.processing = "measured";
  params.measured_time_factor = 20.0;
  slam::StepReport report;
  EXPECT_DOUBLE_EQ(ProcessingSeconds(params, report, true, 5000.0), 0.1);  // 5 ms x 20
}

TEST(ControlTest, BadValuesAreNamed) {
  ControlParams params;
  EXPECT_TRUE(params.Validate().empty());
  params.driver = "joystick";
  params.pose_source = "gps";  // RunConfig::Validate's, which knows the filters
  params.processing = "guess";
  params.measured_time_factor = 0.0;
  const std::vector<ParamProblem> problems = params.Validate();
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_EQ(problems[0].key, "driver");
  EXPECT_EQ(problems[1].key, "processing");
  EXPECT_EQ(problems[2].key, "measured_time_factor");
}

}  // namespace
}  // namespace mjslam::app
