#include <cmath>

#include <gtest/gtest.h>

#include "common/rng.h"

namespace mjslam {
namespace {

TEST(RngTest, SameSeedGivesSameNumbers) {
  Rng a(42);
  Rng b(42);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(a.Gaussian(0.0, 1.0), b.Gaussian(0.0, 1.0));
}

TEST(RngTest, ForkDependsOnNameAndSeedOnlyNotOnDraws) {
  Rng root(7);
  const Rng laser_before = root.Fork("laser");
  root.Uniform();
  root.Uniform();
  Rng laser_after = root.Fork("laser");
  Rng laser_copy = laser_before;
  EXPECT_EQ(laser_copy.Uniform(), laser_after.Uniform());
  Rng odometry = root.Fork("odometry");
  Rng laser = root.Fork("laser");
  EXPECT_NE(odometry.Uniform(), laser.Uniform());
  EXPECT_NE(Rng(7).Fork("laser").seed(), Rng(8).Fork("laser").seed());
}

// Seed 3, 200000 draws: the standard error of the mean is 0.5 / sqrt(2e5) =
// 0.0011 and of the variance about 0.0016 (times 4 for sigma 2); bounds are 5
// standard errors.
TEST(RngTest, GaussianHasRequestedMoments) {
  Rng rng(3);
  const int n = 200000;
  double sum = 0.0;
  double sum_sq = 0.0;
  for (int i = 0; i < n; ++i) {
    const double x = rng.Gaussian(1.5, 0.5);
    sum += x;
    sum_sq += x * x;
  }
  const double mean = sum / n;
  const double variance = sum_sq / n - mean * mean;
  EXPECT_NEAR(mean, 1.5, 0.0056);
  EXPECT_NEAR(variance, 0.25, 0.0080);
}

TEST(RngTest, BernoulliFrequencyMatchesProbability) {
  Rng rng(11);
  const int n = 100000;
  int hits = 0;
  for (int i = 0; i < n; ++i) hits += rng.Bernoulli(0.2) ? 1 : 0;
  // Standard error sqrt(0.2 * 0.8 / n) = 0.00126; bound 5 of them.
  EXPECT_NEAR(static_cast<double>(hits) / n, 0.2, 0.0064);
}

}  // namespace
}  // namespace mjslam
