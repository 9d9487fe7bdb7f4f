// examples/dead_reckoning_filter.cc through the registry, as the closed loop
// builds it: its pose is the odometry's, its covariance that of the EKF's
// prediction, and it runs in a FilterBank beside the paper's two.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "app/engine/control.h"
#include "app/engine/filter_bank.h"
#include "common/records.h"
#include "slam/ekf_slam.h"
#include "slam/filter.h"

namespace mjslam::examples {
namespace {

constexpr double kDt = 0.1;

// Records of an arc: 0.3 m/s and 0.4 rad/s of the axle centre, odometry
// exact, no scans.
std::vector<SensorRecord> ArcRecords(int n) {
  std::vector<SensorRecord> records;
  for (int k = 0; k < n; ++k) {
    SensorRecord record;
    record.t_s = k * kDt;
    record.dt_s = k == 0 ? 0.0 : kDt;
    const double th = 0.4 * record.t_s;
    record.X_OR = Pose2(0.75 * std::sin(th), 0.75 * (1.0 - std::cos(th)), th);
    records.push_back(record);
  }
  return records;
}

slam::SlamParams WithDeadReckoning() {
  slam::SlamParams params;
  // Eq. (6) alone: the example leaves out the EKF's skid and lateral slip.
  slam::OdometryProcessModel model;
  model.lateral.skid_s = 0.0;
  model.lateral.slip_std_m_per_rad = 0.0;
  model.lateral.slip_std_m_per_sqrt_m = 0.0;
  params.ekf.process_model = model;
  slam::FilterParams classical;
  classical.name = "classical";
  classical.update = "classical";
  slam::FilterParams dead_reckoning;
  dead_reckoning.name = "dead_reckoning";
  dead_reckoning.kind = "dead_reckoning";
  params.filters = {classical, dead_reckoning};
  return params;
}

TEST(DeadReckoningFilterTest, IsARegisteredKind) {
  EXPECT_TRUE(slam::FilterRegistry::Global().Has("dead_reckoning"));
  EXPECT_TRUE(WithDeadReckoning().Validate().empty());
}

// Without scans the EKF only predicts: the dead-reckoning filter, which
// predicts with the same motion model and noise (no skid or lateral slip
// here), gives the same pose and covariance.
TEST(DeadReckoningFilterTest, EqualsThePredictionOfTheEkf) {
  const slam::SlamParams params = WithDeadReckoning();
  app::FilterBank bank(params, app::ControlParams{}, kDt, Pose2(), Pose2(), Rng(1));
  for (const SensorRecord& record : ArcRecords(30)) bank.Step(record);
  const slam::Filter& ekf = bank.filter(0);
  const slam::Filter& dead_reckoning = bank.filter(1);
  EXPECT_NEAR(dead_reckoning.X_WR().x, ekf.X_WR().x, 1e-12);
  EXPECT_NEAR(dead_reckoning.X_WR().y, ekf.X_WR().y, 1e-12);
  EXPECT_NEAR(dead_reckoning.X_WR().theta, ekf.X_WR().theta, 1e-12);
  EXPECT_TRUE(dead_reckoning.pose_covariance().isApprox(ekf.pose_covariance(), 1e-9))
      << dead_reckoning.pose_covariance() << "\n" << ekf.pose_covariance();
  EXPECT_GT(dead_reckoning.pose_covariance()(0, 0), 0.0);
  EXPECT_EQ(dead_reckoning.num_features(), 0);
  EXPECT_TRUE(dead_reckoning.Map().empty());
  EXPECT_EQ(bank.Rows(Pose2()).size(), 2u);
}

}  // namespace
}  // namespace mjslam::examples
