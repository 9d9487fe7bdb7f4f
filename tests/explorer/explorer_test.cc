// Explorer::Step's initial turn and its end when nothing is left to explore;
// the closed-loop tests (explorer_closed_loop_test.cc, explorer_worlds_test.cc)
// cover goals, replanning and the safety layer in worlds.

#include "explorer/explorer.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/pose2.h"

namespace mjslam::explorer {
namespace {

constexpr double kDt = 0.1;
constexpr double kA = 0.15;

TEST(ExplorerTest, TurnsInPlaceWithRampedRateUntilTheInitialTurnIsDone) {
  ExplorerParams params;
  params.initial_turn_deg = 90.0;
  Explorer explorer(params, kA);
  const Pose2 X_RS;
  // The robot turns exactly as commanded; no scan arrives.
  Pose2 X_WR(1.0, 2.0, 0.3);
  double previous_w = 0.0;
  double turned = 0.0;
  int step = 0;
  for (; step < 100 && turned < DegToRad(90.0); ++step) {
    const ExplorerOutput output = explorer.Step(X_WR, nullptr, X_RS, step * kDt, kDt);
    ASSERT_FALSE(output.finished) << step;
    EXPECT_EQ(output.command.v_mps, 0.0) << step;
    // Half the top rate, reached at the angular acceleration limit.
    const double expected_w =
        std::min(previous_w + params.max_angular_accel_radps2 * kDt,
                 0.5 * params.max_angular_speed_radps);
    EXPECT_NEAR(output.command.w_radps, expected_w, 1e-12) << step;
    EXPECT_FALSE(output.safety_active) << step;
    previous_w = output.command.w_radps;
    turned += output.command.w_radps * kDt;
    X_WR.theta = WrapAngle(X_WR.theta + output.command.w_radps * kDt);
  }
  ASSERT_LT(step, 100);
  // Turned: exploring starts, and with an empty map there is no frontier.
  const ExplorerOutput output = explorer.Step(X_WR, nullptr, X_RS, step * kDt, kDt);
  EXPECT_TRUE(output.finished);
  EXPECT_EQ(output.finish_reason, "no_frontier");
  EXPECT_EQ(output.command.v_mps, 0.0);
  EXPECT_EQ(output.command.w_radps, 0.0);
  EXPECT_TRUE(explorer.finished());
  EXPECT_FALSE(explorer.goal().has_value());
  // Finished for good.
  const ExplorerOutput later = explorer.Step(X_WR, nullptr, X_RS, (step + 1) * kDt, kDt);
  EXPECT_TRUE(later.finished);
  EXPECT_EQ(later.command.w_radps, 0.0);
}

TEST(ExplorerTest, WithoutAnInitialTurnChoosesAGoalAtOnce) {
  ExplorerParams params;
  params.initial_turn_deg = 0.0;
  Explorer explorer(params, kA);
  const ExplorerOutput output = explorer.Step(Pose2(), nullptr, Pose2(), 0.0, kDt);
  EXPECT_TRUE(output.finished);
  EXPECT_EQ(output.finish_reason, "no_frontier");
}

}  // namespace
}  // namespace mjslam::explorer
