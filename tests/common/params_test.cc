#include <gtest/gtest.h>

#include "common/params.h"

namespace mjslam {
namespace {

TEST(ParamCheckerTest, CollectsEveryProblemWithKeyValueAndExpectation) {
  ParamChecker check;
  check.Positive("rate_hz", 0.0);
  check.InRange("probability", 1.5, 0.0, 1.0);
  check.NonNegative("count", 3);
  check.OneOf("input", std::string("wheels"), {"command", "odometry"});
  ASSERT_EQ(check.problems().size(), 3u);
  EXPECT_EQ(check.problems()[0].key, "rate_hz");
  EXPECT_EQ(check.problems()[0].value, "0");
  EXPECT_EQ(check.problems()[1].value, "1.5");
  EXPECT_EQ(check.problems()[1].expected, "a value in [0, 1]");
  EXPECT_EQ(check.problems()[2].expected, "one of command, odometry");
}

TEST(ParamCheckerTest, MergePrefixesNestedKeys) {
  ParamChecker inner;
  inner.Positive("max_range_m", -1.0);
  ParamChecker outer;
  outer.Merge("laser", inner.problems());
  ASSERT_EQ(outer.problems().size(), 1u);
  EXPECT_EQ(outer.problems()[0].key, "laser.max_range_m");
}

TEST(ParamCheckerTest, ThrowIfProblemsListsAllLines) {
  ParamChecker check;
  check.Positive("a", -1.0);
  check.Positive("b", -2.0);
  try {
    ThrowIfProblems(check.problems(), "cfg.yaml");
    FAIL() << "expected ParamError";
  } catch (const ParamError& error) {
    EXPECT_STREQ(error.what(),
                 "cfg.yaml: a: expected a value > 0 (got -1)\n"
                 "cfg.yaml: b: expected a value > 0 (got -2)");
  }
  EXPECT_NO_THROW(ThrowIfProblems({}));
}

TEST(ValueTextTest, PrintsShortestRoundTrip) {
  EXPECT_EQ(ValueText(0.1), "0.1");
  EXPECT_EQ(ValueText(1e-9), "1e-09");
  EXPECT_EQ(ValueText(true), "true");
  EXPECT_EQ(ValueText(std::string("x")), "x");
}

}  // namespace
}  // namespace mjslam
