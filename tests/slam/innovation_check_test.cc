// The innovation consistency check (slam/innovation_check.h) on drawn NIS
// values: its truncated chi-square moments, quiet on consistent innovations,
// firing on innovations twice their stated variance.
#include "slam/innovation_check.h"

#include <cmath>

#include <gtest/gtest.h>

#include "common/rng.h"
#include "slam/data_association.h"

namespace mjslam::slam {
namespace {

// A 2-dof chi-square draw truncated at `gate` (exponential with mean 2), by
// rejection, times `scale`.
double DrawNis(Rng* rng, double gate, double scale) {
  for (;;) {
    const double x = -2.0 * std::log(1.0 - rng->Uniform()) * scale;
    if (x < gate) return x;
  }
}

// Feeds `seconds` of 10 Hz steps with 8 matched observations each.
InnovationCheckResult Feed(double scale, double seconds, std::uint64_t seed) {
  const double gate = ChiSquare2Quantile(0.99);
  InnovationCheck check(InnovationCheckParams{}, gate);
  Rng rng(seed);
  for (int step = 0; step * 0.1 < seconds; ++step) {
    double sum = 0.0;
    for (int i = 0; i < 8; ++i) sum += DrawNis(&rng, gate, scale);
    check.Add(step * 0.1, sum, 8);
  }
  return check.result();
}

TEST(InnovationCheckTest, TruncatedMomentsMatchDraws) {
  const double gate = ChiSquare2Quantile(0.99);
  Rng rng(7);
  double sum = 0.0, sum2 = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double x = DrawNis(&rng, gate, 1.0);
    sum += x;
    sum2 += x * x;
  }
  const double mean = sum / n;
  // Standard error of the mean about 0.004: a 0.02 tolerance is 5 of them.
  EXPECT_NEAR(mean, InnovationCheck::TruncatedMean(gate), 0.02);
  EXPECT_NEAR(sum2 / n - mean * mean, InnovationCheck::TruncatedVariance(gate), 0.05);
  EXPECT_NEAR(InnovationCheck::TruncatedMean(gate), 1.907, 0.001);
}

TEST(InnovationCheckTest, QuietOnConsistentInnovations) {
  // 20 runs of 600 s (seeds 1..20): 120 windows each; a window fails with
  // probability 0.001, three in a row about 1e-9.
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const InnovationCheckResult result = Feed(1.0, 600.0, seed);
    EXPECT_EQ(result.windows, 119) << seed;
    EXPECT_FALSE(result.inconsistent()) << seed;
    EXPECT_LE(result.failed_windows, 3) << seed;
  }
}

TEST(InnovationCheckTest, FiresOnInflatedInnovations) {
  // Innovations twice their stated variance (a filter overconfident by that
  // much in S): every seed is reported, within the first windows.
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const InnovationCheckResult result = Feed(2.0, 120.0, seed);
    ASSERT_TRUE(result.inconsistent()) << seed;
    EXPECT_LE(*result.inconsistent_since_s, 20.0) << seed;
  }
}

TEST(InnovationCheckTest, RejectsBadSettings) {
  InnovationCheckParams params;
  params.window_s = 0.0;
  params.probability = 1.0;
  params.sustained_windows = 0;
  EXPECT_EQ(params.Validate().size(), 3u);
}

}  // namespace
}  // namespace mjslam::slam
