// Kind "submaps": JoinSubmap carries a submap to W and fuses the features it
// shares with the global map; without a join the filter is the EKF itself.

#include "slam/submap_filter.h"

#include <cmath>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "slam/ekf_filter.h"
#include "slam/filter.h"
#include "slam/innovation_check.h"
#include "slam/data_association.h"
#include "slam/observation_models.h"
#include "tests/slam/ekf_test_utils.h"

namespace mjslam::slam {
namespace {

LineObservation Line(double rho, double alpha, const Eigen::Vector2d& p_SA,
                     const Eigen::Vector2d& p_SB) {
  LineObservation line;
  line.rho_m = rho;
  line.alpha_rad = alpha;
  line.covariance = Eigen::Vector2d(0.01 * 0.01, 0.002 * 0.002).asDiagonal();
  line.p_SA = p_SA;
  line.p_SB = p_SB;
  return line;
}

// Two walls (x = 2 and y = 1.5) and a lone corner, seen from the origin.
ScanFeatures Walls() {
  ScanFeatures features;
  features.lines.push_back(Line(2.0, 0.0, {2.0, -1.0}, {2.0, 1.5}));
  features.lines.push_back(Line(1.5, kPi / 2.0, {0.0, 1.5}, {2.0, 1.5}));
  CornerObservation corner;
  corner.range_m = 3.0;
  corner.bearing_rad = -0.5;
  corner.covariance = Eigen::Vector2d(0.02 * 0.02, 0.005 * 0.005).asDiagonal();
  corner.p_SC = 3.0 * Eigen::Vector2d(std::cos(-0.5), std::sin(-0.5));
  features.corners.push_back(corner);
  return features;
}

EkfParams Params() {
  EkfParams params;
  params.process_model = CommandProcessModel{};
  return params;
}

// A submap that saw Walls() once from its origin.
EkfSlam SubmapOfWalls() {
  EkfSlam submap(Params(), CorrectionMode::kClassical, Pose2(), Pose2());
  const ScanFeatures walls = Walls();
  submap.Step(SensorRecord{}, &walls);
  return submap;
}

double Gate() { return ChiSquare2Quantile(0.99); }

TEST(JoinSubmapTest, CarriesTheSubmapToItsBase) {
  const EkfSlam submap = SubmapOfWalls();
  JoinedMap map;
  map.mean = Eigen::Vector3d(1.0, -2.0, 0.5);
  int next_id = 0;
  const JoinReport report = JoinSubmap(submap, LinkOf(map, {}), Params(), &map, &next_id);
  EXPECT_EQ(report.num_matched, 0);
  EXPECT_EQ(report.num_new, 3);
  ASSERT_EQ(map.num_features(), 3);
  EXPECT_EQ(next_id, 3);
  // The robot stayed at the submap's origin: the new base is the old one.
  EXPECT_NEAR((map.mean.head<3>() - Eigen::Vector3d(1.0, -2.0, 0.5)).norm(), 0.0, 1e-12);
  const Pose2 X_WB(1.0, -2.0, 0.5);
  Eigen::Matrix2d R;
  R << std::cos(0.5), -std::sin(0.5), std::sin(0.5), std::cos(0.5);
  // The wall x = 2 of B: normal at 0.5 rad, r = 2 + (1, -2) . n.
  const double al = 0.5;
  EXPECT_NEAR(map.mean(4), al, 1e-9);
  EXPECT_NEAR(map.mean(3), 2.0 + std::cos(al) * 1.0 - 2.0 * std::sin(al), 1e-9);
  // The corner: p_W = X_WB p_B, covariance R P R^T (the base is exact).
  const Eigen::Vector2d p_B = submap.slam_state().feature(2);
  EXPECT_NEAR((map.mean.segment<2>(7) - X_WB * p_B).norm(), 0.0, 1e-12);
  const Eigen::Matrix2d P_W = R * submap.slam_state().feature_covariance(2) * R.transpose();
  EXPECT_NEAR((map.covariance.block<2, 2>(7, 7) - P_W).norm(), 0.0, 1e-15);
}

TEST(JoinSubmapTest, CarriesTheBasesUncertaintyToFirstOrder) {
  // The base uncertain: each feature's covariance in W is J P J^T over the
  // base and the feature, J by central differences of the carrying to W.
  const EkfSlam submap = SubmapOfWalls();
  JoinedMap map;
  map.mean = Eigen::Vector3d(3.0, -1.0, 0.7);
  map.covariance = Eigen::Vector3d(0.04, 0.09, 0.01).asDiagonal();
  map.covariance(0, 2) = map.covariance(2, 0) = 0.01;
  int next_id = 0;
  JoinedMap joined = map;
  JoinSubmap(submap, LinkOf(map, {}), Params(), &joined, &next_id);
  const SlamState& s = submap.slam_state();
  for (int k = 0; k < 3; ++k) {
    const FeatureType type = s.feature_type(k);
    const auto to_world = [&](const Eigen::Matrix<double, 5, 1>& v) {
      const Pose2 X_WB(v(0), v(1), v(2));
      const Eigen::Vector2d f = v.tail<2>();
      if (type == FeatureType::kCorner) return Eigen::Vector2d(X_WB * f);
      // The line through two of its points, carried to W.
      const Eigen::Vector2d n(std::cos(f.y()), std::sin(f.y()));
      const Eigen::Vector2d t(-n.y(), n.x());
      const Eigen::Vector2d a = X_WB * Eigen::Vector2d(f.x() * n);
      const Eigen::Vector2d b = X_WB * Eigen::Vector2d(f.x() * n + t);
      const Eigen::Vector2d d = (b - a).normalized();
      const Eigen::Vector2d n_W(d.y(), -d.x());
      return CanonicalLine(Eigen::Vector2d(n_W.dot(a), std::atan2(n_W.y(), n_W.x())));
    };
    Eigen::Matrix<double, 5, 1> v;
    v << map.mean, s.feature(k);
    const Eigen::Matrix<double, 2, 5> J = testing::NumericalJacobian<2, 5>(
        to_world, v, type == FeatureType::kLine ? std::initializer_list<int>{1}
                                                : std::initializer_list<int>{});
    Eigen::Matrix<double, 5, 5> P = Eigen::Matrix<double, 5, 5>::Zero();
    P.topLeftCorner<3, 3>() = map.covariance;
    P.bottomRightCorner<2, 2>() = s.feature_covariance(k);
    const Eigen::Matrix2d expected = J * P * J.transpose();
    const Eigen::Matrix2d got = joined.covariance.block<2, 2>(3 + 2 * k, 3 + 2 * k);
    EXPECT_NEAR((got - expected).norm(), 0.0, 1e-6 * expected.norm()) << "feature " << k;
  }
}

TEST(JoinSubmapTest, FusesTheFeaturesASecondSubmapSeesAgain) {
  JoinedMap map;
  int next_id = 0;
  JoinSubmap(SubmapOfWalls(), LinkOf(map, {}), Params(), &map, &next_id);
  const Eigen::Matrix2d P_first = map.covariance.block<2, 2>(3, 3);
  // The same walls seen again from the same place, in a new submap.
  const JoinReport report = JoinSubmap(SubmapOfWalls(), LinkOf(map, {}), Params(), &map, &next_id);
  EXPECT_EQ(report.num_matched, 3);
  EXPECT_EQ(report.num_new, 0);
  EXPECT_EQ(map.num_features(), 3);
  EXPECT_EQ(next_id, 3);
  // Two independent looks at a wall from an exact pose: half the variance,
  // fused with the join's residue of (1 mm, 0.1 mrad)^2 as the noise of
  // their difference: P - P (2 P + R)^-1 P.
  const Eigen::Matrix2d R = Eigen::Vector2d(1e-6, 1e-8).asDiagonal();
  const Eigen::Matrix2d expected = P_first - P_first * (2.0 * P_first + R).inverse() * P_first;
  EXPECT_NEAR(map.covariance(3, 3), expected(0, 0), 1e-6 * P_first(0, 0));
  EXPECT_NEAR(map.covariance(4, 4), expected(1, 1), 1e-6 * P_first(1, 1));
  EXPECT_GT(map.covariance(3, 3), 0.5 * P_first(0, 0));
}

TEST(JoinSubmapTest, AWallSeenFromItsOtherSideIsNotFused) {
  JoinedMap map;
  int next_id = 0;
  JoinSubmap(SubmapOfWalls(), LinkOf(map, {}), Params(), &map, &next_id);
  // The wall x = 2 seen from x = 4 (its other face), as the only feature.
  EkfSlam other(Params(), CorrectionMode::kClassical, Pose2(), Pose2());
  ScanFeatures back;
  back.lines.push_back(Line(2.0, kPi, {-2.0, 1.0}, {-2.0, -1.0}));
  other.Step(SensorRecord{}, &back);
  map.mean.head<3>() = Eigen::Vector3d(4.0, 0.0, 0.0);
  const JoinReport report = JoinSubmap(other, LinkOf(map, {}), Params(), &map, &next_id);
  EXPECT_EQ(report.num_matched, 0);
  EXPECT_EQ(map.num_features(), 4);
}

FilterSettings Settings(int max_features) {
  FilterSettings settings;
  settings.slam.ekf = Params();
  settings.filter.name = "submaps";
  settings.filter.kind = "submaps";
  settings.filter.update = "classical";
  settings.filter.submap_max_features = max_features;
  return settings;
}

TEST(SubmapFilterTest, IsTheEkfUntilItsFirstJoin) {
  SubmapFilter submaps(Settings(1000), Pose2(), Pose2(), Rng(1));
  EkfFilter ekf(Settings(1000), Pose2(), Pose2(), Rng(1));
  const ScanFeatures walls = Walls();
  SensorRecord record;
  for (int i = 0; i < 20; ++i) {
    record.dt_s = 0.1;
    record.command = {0.1, 0.05};
    submaps.Step(record, &walls);
    ekf.Step(record, &walls);
  }
  EXPECT_NEAR((submaps.X_WR().translation() - ekf.X_WR().translation()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((submaps.pose_covariance() - ekf.pose_covariance()).norm(), 0.0, 1e-15);
  EXPECT_EQ(submaps.Map().size(), ekf.Map().size());
  EXPECT_EQ(submaps.num_joins(), 0);
}

TEST(SubmapFilterTest, ClosesASubmapWhenItIsFullAndKeepsOneMap) {
  SubmapFilter submaps(Settings(3), Pose2(), Pose2(), Rng(1));
  const ScanFeatures walls = Walls();
  // The first scan filled the submap; each later one starts a new submap
  // whose features are those of the global map. A step that joins reports
  // the join's time as run beside the filter (left out of measured time).
  EXPECT_EQ(submaps.Step(SensorRecord{}, &walls).beside_us, 0.0);
  EXPECT_GT(submaps.Step(SensorRecord{}, &walls).beside_us, 0.0);
  EXPECT_GT(submaps.Step(SensorRecord{}, &walls).beside_us, 0.0);
  EXPECT_EQ(submaps.num_joins(), 2);
  EXPECT_EQ(submaps.global_map().num_features(), 3);
  EXPECT_EQ(submaps.Map().size(), 3u);
}

TEST(SubmapFilterTest, KindIsRegisteredAndItsSizeValidated) {
  EXPECT_TRUE(FilterRegistry::Global().Has("submaps"));
  FilterParams entry = Settings(0).filter;
  const std::vector<ParamProblem> problems = entry.Validate();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].key, "submap_max_features");
  EXPECT_THROW(SubmapFilter(Settings(0), Pose2(), Pose2(), Rng(1)), ParamError);
}

}  // namespace
}  // namespace mjslam::slam
