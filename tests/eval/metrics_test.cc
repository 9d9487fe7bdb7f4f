// Chi-square bounds, pose metrics and map matching.
#include <cmath>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/rng.h"
#include "common/chi_square.h"
#include "eval/map_matching.h"
#include "eval/pose_metrics.h"

namespace mjslam::eval {
namespace {

TEST(ChiSquareTest, QuantilesMatchTables) {
  // Standard table values.
  EXPECT_NEAR(ChiSquareQuantile(0.95, 2.0), 5.991, 1e-3);
  EXPECT_NEAR(ChiSquareQuantile(0.99, 2.0), 9.210, 1e-3);
  EXPECT_NEAR(ChiSquareQuantile(0.975, 3.0), 9.348, 1e-3);
  EXPECT_NEAR(ChiSquareQuantile(0.025, 3.0), 0.2158, 1e-4);
  EXPECT_NEAR(ChiSquareQuantile(0.5, 1.0), 0.4549, 1e-4);
  // 2 dof: closed form -2 ln(1 - p).
  for (const double p : {0.01, 0.3, 0.9, 0.9999}) {
    EXPECT_NEAR(ChiSquareQuantile(p, 2.0), -2.0 * std::log(1.0 - p), 1e-9);
    EXPECT_NEAR(ChiSquareCdf(-2.0 * std::log(1.0 - p), 2.0), p, 1e-12);
  }
  EXPECT_EQ(ChiSquareCdf(0.0, 3.0), 0.0);
}

TEST(ChiSquareTest, AverageNeesBoundsMatchMethodReferenceValues) {
  // docs/method.md, "Consistency: NEES and its bounds": pose, 3 dof, 95 % two-sided.
  const struct {
    int n;
    double lower, upper;
  } cases[] = {{25, 2.118, 4.034}, {50, 2.360, 3.716}, {100, 2.539, 3.499}};
  for (const auto& c : cases) {
    const Interval bounds = AverageNeesBounds(c.n, 3);
    EXPECT_NEAR(bounds.lower, c.lower, 1e-3) << c.n;
    EXPECT_NEAR(bounds.upper, c.upper, 1e-3) << c.n;
  }
  // One run: the chi-square quantiles themselves.
  EXPECT_NEAR(AverageNeesBounds(1, 3).upper, 9.348, 1e-3);
}

TEST(PoseMetricsTest, ErrorWrapsHeadingAndNeesIsMahalanobis) {
  const Pose2 truth(1.0, 2.0, kPi - 0.01);
  const Pose2 estimate(1.1, 1.8, -kPi + 0.02);
  const Eigen::Matrix3d P = Eigen::Vector3d(0.01, 0.04, 0.0009).asDiagonal();
  const PoseStepMetrics m = EvaluatePoseStep(truth, estimate, P);
  EXPECT_NEAR(m.error(0), 0.1, 1e-12);
  EXPECT_NEAR(m.error(1), -0.2, 1e-12);
  EXPECT_NEAR(m.error(2), 0.03, 1e-12);
  EXPECT_NEAR(m.nees, 1.0 + 1.0 + 1.0, 1e-9);
  EXPECT_TRUE(m.inside_2sigma[0] && m.inside_2sigma[1]);
  EXPECT_TRUE(m.inside_2sigma[2]);  // 0.03 <= 2 * 0.03
  const PoseStepMetrics outside = EvaluatePoseStep(truth, Pose2(1.0, 2.0, kPi - 0.08), P);
  EXPECT_FALSE(outside.inside_2sigma[2]);
  // A correlated covariance: NEES = e^T P^-1 e.
  Eigen::Matrix3d C;
  C << 0.02, 0.01, 0.0, 0.01, 0.03, 0.001, 0.0, 0.001, 0.002;
  const PoseStepMetrics c = EvaluatePoseStep(truth, estimate, C);
  EXPECT_NEAR(c.nees, c.error.dot(C.inverse() * c.error), 1e-9);
}

TEST(PoseMetricsTest, ZeroCovarianceHasNoNeesButCountsAZeroErrorInside) {
  const PoseStepMetrics m = EvaluatePoseStep(Pose2(1, 2, 3), Pose2(1, 2, 3), Eigen::Matrix3d::Zero());
  EXPECT_TRUE(std::isnan(m.nees));
  EXPECT_TRUE(m.inside_2sigma[0] && m.inside_2sigma[1] && m.inside_2sigma[2]);
  // Rank 2 up to rounding (seen after the first prediction from P = 0): no
  // NEES, where a plain inverse would give ~1e11.
  Eigen::Matrix3d J;
  J << 1.0, 0.2, 0.0, 0.3, 1.0, 0.0, 0.1, 0.4, 0.0;
  const Eigen::Matrix3d rank2 = 1e-6 * J * J.transpose() + 1e-24 * Eigen::Matrix3d::Identity();
  const PoseStepMetrics r = EvaluatePoseStep(Pose2(1, 2, 0), Pose2(1.001, 2, 0.001), rank2);
  EXPECT_TRUE(std::isnan(r.nees)) << r.nees;
}

TEST(PoseMetricsTest, SummaryOfGaussianErrorsIsConsistent) {
  // Seed 7: 4000 errors drawn from P; the mean NEES is 3 within 0.15 (its
  // standard deviation is sqrt(6 / 4000) = 0.039), about 95.4 % inside 2 sigma.
  Rng rng(7);
  const Eigen::Vector3d sigma(0.1, 0.05, 0.02);
  const Eigen::Matrix3d P = sigma.cwiseProduct(sigma).asDiagonal();
  std::vector<PoseStepMetrics> steps;
  for (int i = 0; i < 4000; ++i) {
    const Pose2 truth(0.0, 0.0, 0.0);
    const Pose2 estimate(rng.Gaussian(0.0, sigma(0)), rng.Gaussian(0.0, sigma(1)),
                         rng.Gaussian(0.0, sigma(2)));
    steps.push_back(EvaluatePoseStep(truth, estimate, P));
  }
  const PoseSummary s = SummarisePoseSteps(steps);
  EXPECT_EQ(s.num_steps, 4000);
  EXPECT_EQ(s.num_nees_steps, 4000);
  EXPECT_NEAR(s.mean_nees, 3.0, 0.15);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(s.inside_2sigma(k), 0.954, 0.015) << k;
    EXPECT_NEAR(s.rmse(k), sigma(k), 0.1 * sigma(k)) << k;
  }
  EXPECT_EQ(s.final_error, steps.back().error);
}

MapFeature Line(double r, double al, Eigen::Vector2d a, Eigen::Vector2d b, double var = 0.0) {
  MapFeature f;
  f.type = MapFeature::Type::kLine;
  f.params = {r, al};
  f.covariance = Eigen::Vector2d(var, var * 0.01).asDiagonal();
  f.has_segment = true;
  f.p_WA = a;
  f.p_WB = b;
  return f;
}

MapFeature Corner(double x, double y, double var = 0.0) {
  MapFeature f;
  f.type = MapFeature::Type::kCorner;
  f.params = {x, y};
  f.covariance = var * Eigen::Matrix2d::Identity();
  return f;
}

TEST(MapMatchingTest, CountsMatchesDuplicatesUnmatchedAndInconsistent) {
  // Truth: the line y = 3 from x = -4 to 4, its collinear twin y = 3 from
  // 6 to 9 (across a door), the line x = 4, two corners.
  const Map truth = {Line(3.0, kPi / 2, {-4, 3}, {4, 3}), Line(3.0, kPi / 2, {6, 3}, {9, 3}),
                     Line(4.0, 0.0, {4, -3}, {4, 3}), Corner(4.0, 3.0), Corner(-4.0, 3.0)};
  const Map estimate = {
      // 0: y = 3.01 seen from x = -2 to 1: the first line, NEES 1.
      Line(3.01, kPi / 2, {-2, 3.01}, {1, 3.01}, 1e-4),
      // 1: the same wall again (duplicate), far off in NEES terms (inconsistent).
      Line(3.05, kPi / 2 + 0.01, {0, 3.05}, {2, 3.05}, 1e-6),
      // 2: the twin across the door, by its segment.
      Line(3.0, kPi / 2, {6.5, 3}, {8, 3}, 1e-4),
      // 3: a line nowhere near any wall.
      Line(1.0, 0.3, {0, 0}, {1, 1}, 1e-4),
      // 4: corner 3 cm off the first corner, covariance 1e-4 per axis: NEES 9.
      Corner(4.0, 3.03, 1e-4),
      // 5: a corner estimate near a line but no true corner.
      Corner(0.0, 3.0, 1e-4)};
  const MapMatchReport r = MatchMaps(estimate, truth);
  ASSERT_EQ(r.truth_index.size(), 6u);
  EXPECT_EQ(r.truth_index[0], 0);
  EXPECT_EQ(r.truth_index[1], 0);
  EXPECT_EQ(r.truth_index[2], 1);
  EXPECT_EQ(r.truth_index[3], -1);
  EXPECT_EQ(r.truth_index[4], 3);
  EXPECT_EQ(r.truth_index[5], -1);
  EXPECT_EQ(r.num_matched_estimates, 4);
  EXPECT_EQ(r.num_matched_truth, 3);
  EXPECT_NEAR(r.matched_fraction, 3.0 / 5.0, 1e-12);
  EXPECT_EQ(r.num_duplicates, 1);
  EXPECT_EQ(r.num_unmatched_estimates, 2);
  EXPECT_EQ(r.num_inconsistent, 1);
  EXPECT_NEAR(r.nees[0], 1.0, 1e-9);
  EXPECT_NEAR(r.nees[4], 9.0, 1e-9);
  EXPECT_TRUE(std::isnan(r.nees[3]));
  EXPECT_NEAR(r.corner_rmse_m, 0.03, 1e-12);
}

TEST(MapMatchingTest, MatchedSeenCountsOnlyTheTruthTheRunSaw) {
  // The truth of the test above; the run saw the first line, the line x = 4
  // and the first corner. The estimates match truth 0 (twice), 1 and 3.
  MapMatchReport r;
  r.num_truth = 5;
  r.truth_index = {0, 0, 1, -1, 3, -1};
  const SeenMatch m = MatchedSeen(r, {1, 0, 1, 1, 0});
  EXPECT_EQ(m.seen, 3);
  EXPECT_NEAR(m.matched_fraction, 2.0 / 3.0, 1e-12);  // truth 0 and 3, not 2
  EXPECT_TRUE(std::isnan(MatchedSeen(r, {0, 0, 0, 0, 0}).matched_fraction));
  EXPECT_THROW(MatchedSeen(r, {1, 1}), std::invalid_argument);
}

TEST(MapMatchingTest, LinesThroughTheOriginMatchInEitherPolarForm) {
  // The line y = 0 seen as (0, pi/2) and estimated as (0.001, -pi/2 + 0.002).
  const Map truth = {Line(0.0, kPi / 2, {-1, 0}, {1, 0})};
  const Map estimate = {Line(0.001, -kPi / 2 + 0.002, {-0.5, 0.001}, {0.5, 0.001}, 1e-6)};
  const MapMatchReport r = MatchMaps(estimate, truth);
  EXPECT_EQ(r.truth_index[0], 0);
  EXPECT_NEAR(r.line_rho_rmse_m, 0.001, 1e-12);
  EXPECT_NEAR(r.line_alpha_rmse_rad, 0.002, 1e-12);
}

TEST(MapMatchingTest, TypesNeverMatchAcrossAndParamsAreValidated) {
  const MapMatchReport r = MatchMaps({Corner(3.0, 1.5707963)}, {Line(3.0, kPi / 2, {0, 3}, {1, 3})});
  EXPECT_EQ(r.truth_index[0], -1);
  MatchParams bad;
  bad.corner_gate_m = -1.0;
  EXPECT_THROW(MatchMaps({}, {}, bad), ParamError);
}

}  // namespace
}  // namespace mjslam::eval
