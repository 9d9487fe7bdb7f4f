// The innovation consistency check (slam/innovation_check.h) on drawn NIS
// values: its truncated chi-square moments, quiet on consistent innovations,
// firing on innovations twice their stated variance; its near-miss test quiet
// on a consistent filter and firing after a pose jump; its copy test
// counting new features near mapped ones and firing on a window of them.
#include "slam/innovation_check.h"

#include <cmath>
#include <limits>
#include <vector>

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

// Feeds `seconds` of 10 Hz scans, each with 6 observations of mapped
// features and 1 of new structure (nearest NIS +inf). From `jump_s` on, the
// pose is `offset_sigmas` off along one direction of each observation's
// innovation: its NIS is (offset + n1)^2 + n2^2 with n1, n2 standard normal
// (0: consistent). Observations under the gate match; the others are near
// misses when under near_miss_max_nis.
InnovationCheckResult FeedScans(double offset_sigmas, double jump_s, double seconds,
                                std::uint64_t seed) {
  const double gate = ChiSquare2Quantile(0.99);
  InnovationCheck check(InnovationCheckParams{}, gate);
  Rng rng(seed);
  for (int step = 0; step * 0.1 < seconds; ++step) {
    const double t = step * 0.1;
    const double offset = t >= jump_s ? offset_sigmas : 0.0;
    std::vector<double> nearest(7, std::numeric_limits<double>::infinity());
    double sum = 0.0;
    int matched = 0;
    for (int i = 0; i < 6; ++i) {
      const double n1 = offset + rng.Gaussian(0.0, 1.0);
      const double n2 = rng.Gaussian(0.0, 1.0);
      nearest[i] = n1 * n1 + n2 * n2;
      if (nearest[i] < gate) {
        sum += nearest[i];
        ++matched;
      }
    }
    check.Add(t, sum, matched, 7, check.NearMisses(nearest));
  }
  return check.result();
}

TEST(InnovationCheckTest, CountsNearMissesBetweenGateAndLimit) {
  const double gate = ChiSquare2Quantile(0.99);
  InnovationCheck check(InnovationCheckParams{}, gate);
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(check.NearMisses({0.5, 9.0, 9.3, 50.0, 99.9, 100.0, 500.0, inf}), 3);
}

TEST(InnovationCheckTest, NearMissTestQuietOnAConsistentFilter) {
  // 20 runs of 600 s (seeds 1..20): a mapped feature's NIS passes the gate
  // with probability 0.01, the window bound is 0.01 + 3.09 sqrt(0.01 0.99 /
  // 50) = 0.053 of its observations; three failing windows in a row are
  // practically impossible.
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const InnovationCheckResult result = FeedScans(0.0, 0.0, 600.0, seed);
    EXPECT_EQ(result.near_miss_windows, 119) << seed;
    EXPECT_FALSE(result.near_miss_since_s.has_value()) << seed;
    EXPECT_FALSE(result.inconsistent()) << seed;
    EXPECT_LE(result.near_miss_failed_windows, 3) << seed;
    EXPECT_NEAR(result.near_miss_fraction, 6.0 / 7.0 * 0.01, 0.004) << seed;
  }
}

TEST(InnovationCheckTest, NearMissTestFiresAfterAPoseJump) {
  // At t = 60 s the pose jumps 4 sigma (in each observation's innovation):
  // most observations of mapped walls now miss the gate, and what still
  // matches has a NIS near the gate's. Every seed is reported by the
  // near-miss test within three windows of the jump.
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const InnovationCheckResult result = FeedScans(4.0, 60.0, 120.0, seed);
    ASSERT_TRUE(result.near_miss_since_s.has_value()) << seed;
    EXPECT_GE(*result.near_miss_since_s, 59.9) << seed;
    EXPECT_LE(*result.near_miss_since_s, 65.1) << seed;
    EXPECT_TRUE(result.inconsistent()) << seed;
  }
  // Off (near_miss_max_nis = 0): no window is judged by it.
  InnovationCheckParams off;
  off.near_miss_max_nis = 0.0;
  InnovationCheck check(off, ChiSquare2Quantile(0.99));
  for (int step = 0; step < 300; ++step) check.Add(step * 0.1, 0.0, 0, 7, 7);
  EXPECT_EQ(check.result().near_miss_windows, 0);
  EXPECT_FALSE(check.result().inconsistent());
}

TEST(InnovationCheckTest, CountsNewFeaturesNearMappedOnesAsCopies) {
  const InnovationCheck check(InnovationCheckParams{}, ChiSquare2Quantile(0.99));
  Association association;
  association.outcome = {AssociationOutcome::kNew, AssociationOutcome::kNew,
                         AssociationOutcome::kNew, AssociationOutcome::kMatched,
                         AssociationOutcome::kAmbiguous, AssociationOutcome::kUnanchored};
  association.feature = {-1, -1, -1, 0, -1, -1};
  // New near a mapped feature (a copy), new far from it, new with no
  // feature of its kind, matched, ambiguous, held back: one copy.
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(check.Copies(association, {30.0, 100.0, inf, 1.0, 12.0, 40.0}), 1);
}

TEST(InnovationCheckTest, CopyTestFiresOnAScanOfCopiesOnly) {
  // A healthy run adds a copy now and then (at most one per scan in the
  // measured runs: quiet even when they come every scan); a scan that
  // becomes new features at a wrong pose adds copies_per_scan at once and
  // is reported at its time.
  const InnovationCheckParams params;
  InnovationCheck check(params, ChiSquare2Quantile(0.99));
  for (int step = 0; step < 1000; ++step) {
    const int copies = step == 620 ? params.copies_per_scan : step % 2 == 0 ? 1 : 0;
    check.Add(step * 0.1, 8.0, 5, 6, 0, copies);
  }
  const InnovationCheckResult result = check.result();
  EXPECT_EQ(result.copied_scans, 1);
  ASSERT_TRUE(result.map_copied_at_s.has_value());
  EXPECT_NEAR(*result.map_copied_at_s, 62.0, 1e-9);
  ASSERT_TRUE(result.inconsistent());
  EXPECT_NEAR(*result.inconsistent_since_s, 62.0, 1e-9);
  EXPECT_EQ(result.copies, 499 + params.copies_per_scan);
  EXPECT_EQ(result.near_miss_failed_windows, 0);
  // Off (copies_per_scan = 0): counted, never judged.
  InnovationCheckParams off;
  off.copies_per_scan = 0;
  InnovationCheck quiet(off, ChiSquare2Quantile(0.99));
  for (int step = 0; step < 300; ++step) quiet.Add(step * 0.1, 8.0, 5, 6, 0, 10);
  EXPECT_EQ(quiet.result().copies, 3000);
  EXPECT_EQ(quiet.result().copied_scans, 0);
  EXPECT_FALSE(quiet.result().inconsistent());
}

TEST(InnovationCheckTest, RejectsBadSettings) {
  InnovationCheckParams params;
  params.window_s = 0.0;
  params.probability = 1.0;
  params.sustained_windows = 0;
  params.near_miss_max_nis = -1.0;
  params.copies_per_scan = -1;
  EXPECT_EQ(params.Validate().size(), 5u);
}

}  // namespace
}  // namespace mjslam::slam
