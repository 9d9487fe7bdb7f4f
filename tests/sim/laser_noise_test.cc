// The laser noise model: configured mean and sigma, dropouts, jitter,
// clamping, independent named streams, reproducibility. Statistical tests
// state their seed and bound (about 4 standard errors).

#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/rng.h"
#include "sim/laser_noise.h"

namespace mjslam::sim {
namespace {

// An exact scan with every beam returning at `range_m`.
LaserScan ExactScan(const LaserParams& laser, double range_m) {
  LaserScan scan;
  scan.angle_min_rad = laser.AngleMinRad();
  scan.angle_increment_rad = laser.AngleIncrementRad();
  scan.max_range_m = laser.max_range_m;
  scan.ranges_m.assign(laser.num_beams, range_m);
  scan.has_return.assign(laser.num_beams, 1);
  return scan;
}

TEST(LaserNoiseTest, ZeroNoiseLeavesTheScanExact) {
  LaserParams laser;
  laser.range_noise_std_m = 0.0;
  LaserNoise noise(laser, Rng(1));
  LaserScan exact = ExactScan(laser, 4.2);
  exact.has_return[7] = 0;
  exact.ranges_m[7] = laser.max_range_m;
  const LaserScan noisy = noise.Apply(exact);
  EXPECT_EQ(noisy.ranges_m, exact.ranges_m);
  EXPECT_EQ(noisy.has_return, exact.has_return);
  for (const double offset : noise.DrawAngleOffsets()) EXPECT_EQ(offset, 0.0);
}

TEST(LaserNoiseTest, RangeNoiseHasTheConfiguredMeanAndSigma) {
  // Seed 2024, 200 scans x 181 beams = 36200 samples.
  const std::uint64_t seed = 2024;
  LaserParams laser;
  laser.range_noise_std_m = 0.005;
  laser.range_bias_m = 0.01;
  LaserNoise noise(laser, Rng(seed));
  const LaserScan exact = ExactScan(laser, 5.0);
  double sum = 0.0;
  double sum_sq = 0.0;
  int n = 0;
  for (int scan = 0; scan < 200; ++scan) {
    const LaserScan noisy = noise.Apply(exact);
    for (int i = 0; i < noisy.size(); ++i) {
      const double error = noisy.ranges_m[i] - 5.0;
      sum += error;
      sum_sq += error * error;
      ++n;
      ASSERT_EQ(noisy.has_return[i], 1);
    }
  }
  const double mean = sum / n;
  const double std = std::sqrt(sum_sq / n - mean * mean);
  std::cout << "seed " << seed << ": mean " << mean << " m, std " << std << " m over " << n
            << " beams\n";
  // Standard error of the mean: 0.005 / sqrt(36200) = 2.6e-5; of the std: 0.37 %.
  EXPECT_NEAR(mean, 0.01, 1.1e-4);
  EXPECT_NEAR(std, 0.005, 0.005 * 0.015);
}

TEST(LaserNoiseTest, DropoutsHaveTheConfiguredRateAndBecomeNoReturns) {
  // Seed 99: 200 scans x 181 beams; binomial standard error 0.0021.
  LaserParams laser;
  laser.dropout_probability = 0.2;
  LaserNoise noise(laser, Rng(99));
  const LaserScan exact = ExactScan(laser, 3.0);
  int dropped = 0;
  int n = 0;
  for (int scan = 0; scan < 200; ++scan) {
    const LaserScan noisy = noise.Apply(exact);
    for (int i = 0; i < noisy.size(); ++i) {
      ++n;
      if (!noisy.has_return[i]) {
        ++dropped;
        EXPECT_EQ(noisy.ranges_m[i], laser.max_range_m);
      }
    }
  }
  EXPECT_NEAR(static_cast<double>(dropped) / n, 0.2, 0.009);
}

TEST(LaserNoiseTest, AngleJitterHasTheConfiguredSigma) {
  // Seed 5: 200 draws x 181 beams; standard error of the std 0.37 %.
  LaserParams laser;
  laser.angle_jitter_std_deg = 0.5;
  LaserNoise noise(laser, Rng(5));
  double sum = 0.0;
  double sum_sq = 0.0;
  int n = 0;
  for (int k = 0; k < 200; ++k) {
    const std::vector<double> offsets = noise.DrawAngleOffsets();
    ASSERT_EQ(static_cast<int>(offsets.size()), laser.num_beams);
    for (const double offset : offsets) {
      sum += offset;
      sum_sq += offset * offset;
      ++n;
    }
  }
  const double mean = sum / n;
  EXPECT_NEAR(mean, 0.0, 4 * DegToRad(0.5) / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(sum_sq / n - mean * mean), DegToRad(0.5), DegToRad(0.5) * 0.015);
}

TEST(LaserNoiseTest, RangesStayWithinZeroAndMaxRange) {
  LaserParams laser;
  laser.max_range_m = 10.0;
  laser.range_noise_std_m = 0.5;
  LaserNoise noise(laser, Rng(3));
  // Near zero: echoes clamped at 0 stay echoes.
  bool clamped = false;
  for (int scan = 0; scan < 20; ++scan) {
    const LaserScan noisy = noise.Apply(ExactScan(laser, 0.01));
    for (int i = 0; i < noisy.size(); ++i) {
      EXPECT_GE(noisy.ranges_m[i], 0.0);
      EXPECT_EQ(noisy.has_return[i], 1);
      clamped = clamped || noisy.ranges_m[i] == 0.0;
    }
  }
  EXPECT_TRUE(clamped);
  // Near the maximum: an echo is a range strictly below it; noise that
  // reaches the maximum makes a no-return at the maximum range.
  int echoes = 0;
  int lost = 0;
  for (int scan = 0; scan < 20; ++scan) {
    const LaserScan noisy = noise.Apply(ExactScan(laser, 9.99));
    for (int i = 0; i < noisy.size(); ++i) {
      if (noisy.has_return[i]) {
        ++echoes;
        EXPECT_LT(noisy.ranges_m[i], 10.0);
      } else {
        ++lost;
        EXPECT_EQ(noisy.ranges_m[i], 10.0);
      }
    }
  }
  EXPECT_GT(echoes, 0);
  EXPECT_GT(lost, 0);
}

TEST(LaserNoiseTest, NoReturnBeamsStayNoReturns) {
  LaserParams laser;
  laser.range_noise_std_m = 0.1;
  laser.range_bias_m = 0.2;
  LaserNoise noise(laser, Rng(4));
  LaserScan exact = ExactScan(laser, 2.0);
  for (int i = 0; i < exact.size(); i += 2) {
    exact.ranges_m[i] = laser.max_range_m;
    exact.has_return[i] = 0;
  }
  const LaserScan noisy = noise.Apply(exact);
  for (int i = 0; i < exact.size(); i += 2) {
    EXPECT_EQ(noisy.has_return[i], 0);
    EXPECT_EQ(noisy.ranges_m[i], laser.max_range_m);
  }
}

TEST(LaserNoiseTest, EachEffectHasItsOwnStream) {
  // Turning dropouts and jitter on does not change the range noise of the
  // beams that keep their echo.
  LaserParams plain;
  LaserParams with_dropouts = plain;
  with_dropouts.dropout_probability = 0.3;
  with_dropouts.angle_jitter_std_deg = 0.2;
  LaserNoise a(plain, Rng(77));
  LaserNoise b(with_dropouts, Rng(77));
  const LaserScan exact = ExactScan(plain, 6.0);
  b.DrawAngleOffsets();
  const LaserScan noisy_a = a.Apply(exact);
  const LaserScan noisy_b = b.Apply(exact);
  int kept = 0;
  for (int i = 0; i < exact.size(); ++i) {
    if (!noisy_b.has_return[i]) continue;
    ++kept;
    EXPECT_EQ(noisy_a.ranges_m[i], noisy_b.ranges_m[i]) << "beam " << i;
  }
  EXPECT_GT(kept, 90);
  EXPECT_LT(kept, exact.size());
}

TEST(LaserNoiseTest, SameSeedSameNoiseOtherSeedOtherNoise) {
  const LaserParams laser;
  const LaserScan exact = ExactScan(laser, 3.0);
  LaserNoise a(laser, Rng(10));
  LaserNoise b(laser, Rng(10));
  LaserNoise c(laser, Rng(11));
  const LaserScan scan_a = a.Apply(exact);
  EXPECT_EQ(scan_a.ranges_m, b.Apply(exact).ranges_m);
  EXPECT_NE(scan_a.ranges_m, c.Apply(exact).ranges_m);
  // Consecutive scans differ.
  EXPECT_NE(scan_a.ranges_m, a.Apply(exact).ranges_m);
}

TEST(LaserNoiseTest, InvalidParamsThrow) {
  LaserParams laser;
  laser.dropout_probability = 1.5;
  EXPECT_THROW(LaserNoise(laser, Rng(1)), ParamError);
}

}  // namespace
}  // namespace mjslam::sim
