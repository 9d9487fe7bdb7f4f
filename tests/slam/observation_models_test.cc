// Observation models (Eqs. 7, 8), their inverses and the motion model (Eq. 6):
// values from geometry and every analytic Jacobian against central differences.

#include "slam/observation_models.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/rng.h"
#include "slam/fast_wrap.h"
#include "slam/motion_model.h"
#include "tests/slam/ekf_test_utils.h"

namespace mjslam::slam {
namespace {

using testing::NumericalJacobian;
using Matrix23 = Eigen::Matrix<double, 2, 3>;

constexpr double kJacobianTolerance = 1e-6;

Eigen::Vector3d RandomPose(Rng* rng) {
  return {rng->Gaussian(0.0, 5.0), rng->Gaussian(0.0, 5.0), kPi * (2.0 * rng->Uniform() - 1.0)};
}

Pose2 RandomMount(Rng* rng) {
  return Pose2(rng->Gaussian(0.1, 0.2), rng->Gaussian(0.0, 0.1), rng->Gaussian(0.0, 0.3));
}

// The line (r, al) in W seen from pose_WS, computed from geometry rather
// than from Eq. (8): a point of the line and its normal moved into S.
Eigen::Vector2d LineInSensorByGeometry(const Pose2& X_WS, const Eigen::Vector2d& line_W) {
  const Eigen::Vector2d n_W(std::cos(line_W.y()), std::sin(line_W.y()));
  const Eigen::Vector2d p_W = line_W.x() * n_W;
  const Pose2 X_SW = X_WS.Inverse();
  const Eigen::Vector2d p_S = X_SW * p_W;
  const Eigen::Vector2d n_S(std::cos(X_SW.theta) * n_W.x() - std::sin(X_SW.theta) * n_W.y(),
                            std::sin(X_SW.theta) * n_W.x() + std::cos(X_SW.theta) * n_W.y());
  double rho = n_S.dot(p_S);
  double alpha = std::atan2(n_S.y(), n_S.x());
  if (rho < 0.0) {
    rho = -rho;
    alpha += kPi;
  }
  return {rho, WrapAngle(alpha)};
}

TEST(FastWrapTest, EqualsWrapAngleExactly) {
  Rng rng(10);
  std::vector<double> angles = {0.0, -0.0, kPi, -kPi, 2.0 * kPi, -2.0 * kPi, 3.0 * kPi,
                                -3.0 * kPi, std::nextafter(kPi, 10.0), std::nextafter(-kPi, -10.0),
                                std::nextafter(3.0 * kPi, 0.0), std::nextafter(-3.0 * kPi, 0.0),
                                1e6, -1e6, 100.0 * kPi + 0.5};
  for (int i = 0; i < 100000; ++i) angles.push_back(20.0 * (2.0 * rng.Uniform() - 1.0));
  for (int i = 0; i < 1000; ++i) angles.push_back(kPi * (1.0 + 1e-12 * rng.Gaussian(0.0, 1.0)));
  for (const double angle : angles) {
    const double fast = WrapAngleFast(angle);
    const double reference = WrapAngle(angle);
    // Exactly equal (only the sign of a zero result may differ).
    ASSERT_EQ(fast, reference) << "angle " << angle;
  }
  EXPECT_TRUE(std::isnan(WrapAngleFast(NAN)));
}

TEST(ObservationModelsTest, SensorPoseComposesMountAndJacobianMatches) {
  Rng rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d pose = RandomPose(&rng);
    const Pose2 X_RS = RandomMount(&rng);
    Eigen::Matrix3d J;
    const Eigen::Vector3d pose_WS = SensorPose(pose, X_RS, &J);
    const Pose2 X_WS = Pose2(pose.x(), pose.y(), pose.z()) * X_RS;
    EXPECT_NEAR(pose_WS.x(), X_WS.x, 1e-12);
    EXPECT_NEAR(pose_WS.y(), X_WS.y, 1e-12);
    EXPECT_NEAR(WrapAngle(pose_WS.z() - X_WS.theta), 0.0, 1e-12);
    const Eigen::Matrix3d numerical = NumericalJacobian<3, 3>(
        [&](const Eigen::Vector3d& p) { return SensorPose(p, X_RS); }, pose, {2});
    EXPECT_LT((J - numerical).cwiseAbs().maxCoeff(), kJacobianTolerance) << "trial " << trial;
  }
}

TEST(ObservationModelsTest, LinePredictionMatchesGeometryAndJacobians) {
  Rng rng(12);
  int flipped = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d pose = RandomPose(&rng);
    const Pose2 X_RS = RandomMount(&rng);
    const Eigen::Vector2d line(3.0 * rng.Uniform() + 0.5, kPi * (2.0 * rng.Uniform() - 1.0));
    const Pose2 X_WS = Pose2(pose.x(), pose.y(), pose.z()) * X_RS;
    const Eigen::Vector2d expected = LineInSensorByGeometry(X_WS, line);
    // Skip lines through the sensor, where the canonical form jumps.
    if (expected.x() < 0.05) continue;
    const double raw_rho = line.x() - X_WS.x * std::cos(line.y()) - X_WS.y * std::sin(line.y());
    if (raw_rho < 0.0) ++flipped;

    Matrix23 H_pose;
    Eigen::Matrix2d H_feature;
    const Eigen::Vector2d z = PredictLine(pose, line, X_RS, &H_pose, &H_feature);
    EXPECT_NEAR(z.x(), expected.x(), 1e-9) << "trial " << trial;
    EXPECT_NEAR(WrapAngle(z.y() - expected.y()), 0.0, 1e-9) << "trial " << trial;
    EXPECT_GE(z.x(), 0.0);
    EXPECT_GT(z.y(), -kPi);
    EXPECT_LE(z.y(), kPi);

    const Matrix23 numerical_pose = NumericalJacobian<2, 3>(
        [&](const Eigen::Vector3d& p) { return PredictLine(p, line, X_RS); }, pose, {1});
    const Eigen::Matrix2d numerical_feature = NumericalJacobian<2, 2>(
        [&](const Eigen::Vector2d& f) { return PredictLine(pose, f, X_RS); }, line, {1});
    EXPECT_LT((H_pose - numerical_pose).cwiseAbs().maxCoeff(), kJacobianTolerance)
        << "trial " << trial;
    EXPECT_LT((H_feature - numerical_feature).cwiseAbs().maxCoeff(), kJacobianTolerance)
        << "trial " << trial;
  }
  // Both branches of the canonicalisation were exercised.
  EXPECT_GT(flipped, 20);
}

TEST(ObservationModelsTest, LineFlipsWhenRhoIsNegative) {
  // The wall x = 1 (r = 1, al = 0) seen from x = 3 facing +x, no mount offset:
  // raw rho = 1 - 3 = -2, so the observation is (2, 0 - 0 + pi).
  const Eigen::Vector3d pose(3.0, 0.5, 0.0);
  const Eigen::Vector2d line(1.0, 0.0);
  Matrix23 H_pose;
  Eigen::Matrix2d H_feature;
  const Eigen::Vector2d z = PredictLine(pose, line, Pose2(), &H_pose, &H_feature);
  EXPECT_NEAR(z.x(), 2.0, 1e-12);
  EXPECT_NEAR(std::abs(z.y()), kPi, 1e-12);
  // The flip negates the rho row: d rho / d x = +cos(al) = 1.
  EXPECT_NEAR(H_pose(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(H_feature(0, 0), -1.0, 1e-12);
  const Matrix23 numerical = NumericalJacobian<2, 3>(
      [&](const Eigen::Vector3d& p) { return PredictLine(p, line, Pose2()); }, pose, {1});
  EXPECT_LT((H_pose - numerical).cwiseAbs().maxCoeff(), kJacobianTolerance);
}

TEST(ObservationModelsTest, LineAngleWrapsAtPi) {
  // al - th = 3.1 + 0.1 = 3.2 > pi: wrapped to 3.2 - 2 pi, and the Jacobian
  // (with wrapped differences) is unaffected by the wrap.
  const Eigen::Vector3d pose(0.0, 0.0, -0.1);
  const Eigen::Vector2d line(2.0, 3.1);
  Matrix23 H_pose;
  Eigen::Matrix2d H_feature;
  const Eigen::Vector2d z = PredictLine(pose, line, Pose2(), &H_pose, &H_feature);
  EXPECT_NEAR(z.y(), 3.2 - 2.0 * kPi, 1e-12);
  const Matrix23 numerical_pose = NumericalJacobian<2, 3>(
      [&](const Eigen::Vector3d& p) { return PredictLine(p, line, Pose2()); }, pose, {1});
  const Eigen::Matrix2d numerical_feature = NumericalJacobian<2, 2>(
      [&](const Eigen::Vector2d& f) { return PredictLine(pose, f, Pose2()); }, line, {1});
  EXPECT_LT((H_pose - numerical_pose).cwiseAbs().maxCoeff(), kJacobianTolerance);
  EXPECT_LT((H_feature - numerical_feature).cwiseAbs().maxCoeff(), kJacobianTolerance);
  // The innovation across the wrap is small, not 2 pi.
  const Eigen::Vector2d observed(2.0, kPi - 0.05);
  EXPECT_NEAR(Innovation(observed, z).y(), kPi - 0.05 - (3.2 - 2.0 * kPi) - 2.0 * kPi, 1e-12);
  EXPECT_LT(std::abs(Innovation(observed, z).y()), 0.2);
}

TEST(ObservationModelsTest, CornerPredictionMatchesGeometryAndJacobians) {
  Rng rng(13);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d pose = RandomPose(&rng);
    const Pose2 X_RS = RandomMount(&rng);
    const Eigen::Vector2d corner(rng.Gaussian(0.0, 5.0), rng.Gaussian(0.0, 5.0));
    const Pose2 X_WS = Pose2(pose.x(), pose.y(), pose.z()) * X_RS;
    const Eigen::Vector2d p_SC = X_WS.Inverse() * corner;
    if (p_SC.norm() < 0.1) continue;

    Matrix23 H_pose;
    Eigen::Matrix2d H_feature;
    const Eigen::Vector2d z = PredictCorner(pose, corner, X_RS, &H_pose, &H_feature);
    EXPECT_NEAR(z.x(), p_SC.norm(), 1e-9);
    EXPECT_NEAR(WrapAngle(z.y() - std::atan2(p_SC.y(), p_SC.x())), 0.0, 1e-9);

    const Matrix23 numerical_pose = NumericalJacobian<2, 3>(
        [&](const Eigen::Vector3d& p) { return PredictCorner(p, corner, X_RS); }, pose, {1});
    const Eigen::Matrix2d numerical_feature = NumericalJacobian<2, 2>(
        [&](const Eigen::Vector2d& f) { return PredictCorner(pose, f, X_RS); }, corner, {1});
    EXPECT_LT((H_pose - numerical_pose).cwiseAbs().maxCoeff(), kJacobianTolerance)
        << "trial " << trial;
    EXPECT_LT((H_feature - numerical_feature).cwiseAbs().maxCoeff(), kJacobianTolerance)
        << "trial " << trial;
  }
}

TEST(ObservationModelsTest, InverseLineModelRoundTripsAndJacobians) {
  Rng rng(14);
  int flipped = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d pose = RandomPose(&rng);
    const Pose2 X_RS = RandomMount(&rng);
    const Eigen::Vector2d z(3.0 * rng.Uniform() + 0.3, kPi * (2.0 * rng.Uniform() - 1.0));
    Matrix23 G_pose;
    Eigen::Matrix2d G_z;
    const Eigen::Vector2d line = InitializeLine(pose, z, X_RS, &G_pose, &G_z);
    // Skip lines through W's origin, where the canonical form jumps.
    if (line.x() < 0.05) continue;
    const Eigen::Vector3d pose_WS = SensorPose(pose, X_RS);
    if (z.x() + pose_WS.x() * std::cos(z.y() + pose_WS.z()) +
            pose_WS.y() * std::sin(z.y() + pose_WS.z()) <
        0.0) {
      ++flipped;
    }
    EXPECT_GE(line.x(), 0.0);
    const Eigen::Vector2d back = PredictLine(pose, line, X_RS);
    EXPECT_NEAR(back.x(), z.x(), 1e-9);
    EXPECT_NEAR(WrapAngle(back.y() - z.y()), 0.0, 1e-9);

    const Matrix23 numerical_pose = NumericalJacobian<2, 3>(
        [&](const Eigen::Vector3d& p) { return InitializeLine(p, z, X_RS); }, pose, {1});
    const Eigen::Matrix2d numerical_z = NumericalJacobian<2, 2>(
        [&](const Eigen::Vector2d& zz) { return InitializeLine(pose, zz, X_RS); }, z, {1});
    EXPECT_LT((G_pose - numerical_pose).cwiseAbs().maxCoeff(), kJacobianTolerance)
        << "trial " << trial;
    EXPECT_LT((G_z - numerical_z).cwiseAbs().maxCoeff(), kJacobianTolerance)
        << "trial " << trial;
  }
  EXPECT_GT(flipped, 20);
}

TEST(ObservationModelsTest, InverseCornerModelRoundTripsAndJacobians) {
  Rng rng(15);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d pose = RandomPose(&rng);
    const Pose2 X_RS = RandomMount(&rng);
    const Eigen::Vector2d z(5.0 * rng.Uniform() + 0.3, kPi * (2.0 * rng.Uniform() - 1.0));
    Matrix23 G_pose;
    Eigen::Matrix2d G_z;
    const Eigen::Vector2d corner = InitializeCorner(pose, z, X_RS, &G_pose, &G_z);
    const Eigen::Vector2d back = PredictCorner(pose, corner, X_RS);
    EXPECT_NEAR(back.x(), z.x(), 1e-9);
    EXPECT_NEAR(WrapAngle(back.y() - z.y()), 0.0, 1e-9);

    const Matrix23 numerical_pose = NumericalJacobian<2, 3>(
        [&](const Eigen::Vector3d& p) { return InitializeCorner(p, z, X_RS); }, pose, {});
    const Eigen::Matrix2d numerical_z = NumericalJacobian<2, 2>(
        [&](const Eigen::Vector2d& zz) { return InitializeCorner(pose, zz, X_RS); }, z, {});
    EXPECT_LT((G_pose - numerical_pose).cwiseAbs().maxCoeff(), kJacobianTolerance)
        << "trial " << trial;
    EXPECT_LT((G_z - numerical_z).cwiseAbs().maxCoeff(), kJacobianTolerance)
        << "trial " << trial;
  }
}

TEST(ObservationModelsTest, MountOffsetChangesThePrediction) {
  // The same robot pose sees a corner differently through a mounted laser.
  const Eigen::Vector3d pose(0.0, 0.0, 0.0);
  const Eigen::Vector2d corner(2.0, 0.0);
  const Eigen::Vector2d without = PredictCorner(pose, corner, Pose2());
  const Eigen::Vector2d with = PredictCorner(pose, corner, Pose2(0.5, 0.0, 0.0));
  EXPECT_NEAR(without.x(), 2.0, 1e-12);
  EXPECT_NEAR(with.x(), 1.5, 1e-12);
}

TEST(MotionModelTest, PredictionIntegratesEquationSixExactly) {
  // Heading pi/2, d = 0.3, dth = 0.1, a = 0.2. Eq. (6) with (u, w) held over
  // the period: the axle centre moves on an arc of length d, the point h
  // stays a ahead of it. Axle at (1, 1.8); it turns by 0.1 on a circle of
  // radius d / dth = 3 about (-2, 1.8), ending at (-2 + 3 cos 0.1, 1.8 + 3 sin 0.1).
  const Eigen::Vector3d pose(1.0, 2.0, kPi / 2.0);
  const Eigen::Vector3d next = PredictPose(pose, Eigen::Vector2d(0.3, 0.1), 0.2);
  const double th = kPi / 2.0 + 0.1;
  EXPECT_NEAR(next.x(), -2.0 + 3.0 * std::cos(0.1) + 0.2 * std::cos(th), 1e-12);
  EXPECT_NEAR(next.y(), 1.8 + 3.0 * std::sin(0.1) + 0.2 * std::sin(th), 1e-12);
  EXPECT_NEAR(next.z(), th, 1e-12);
  // Without turning it is a straight move of d along the heading.
  const Eigen::Vector3d straight = PredictPose(pose, Eigen::Vector2d(0.3, 0.0), 0.2);
  EXPECT_NEAR(straight.x(), 1.0, 1e-12);
  EXPECT_NEAR(straight.y(), 2.3, 1e-12);
  // Small steps agree with the paper's forward-Euler form to second order:
  // x' = x + d cos th - a dth sin th, y' = y + d sin th + a dth cos th.
  const Eigen::Vector3d small = PredictPose(pose, Eigen::Vector2d(3e-3, 1e-3), 0.2);
  EXPECT_NEAR(small.x(), 1.0 - 0.2 * 1e-3, 1e-5);
  EXPECT_NEAR(small.y(), 2.0 + 3e-3, 1e-5);
  // Heading is wrapped.
  const Eigen::Vector3d wrapped = PredictPose(Eigen::Vector3d(0, 0, 3.1), Eigen::Vector2d(0, 0.1), 0.2);
  EXPECT_NEAR(wrapped.z(), 3.2 - 2.0 * kPi, 1e-12);
}

TEST(MotionModelTest, SkidMovesROutwardAcrossTheMidArcHeading) {
  // Heading 0, d = 0.3, dth = 0.1 (a left turn), skid 0.05 per metre and
  // radian: R ends 0.05 * 0.3 * 0.1 = 1.5 mm further right, across the
  // mid-arc heading 0.05, than without skid; the heading is unchanged.
  const Eigen::Vector3d pose(1.0, 2.0, 0.0);
  const Eigen::Vector2d increment(0.3, 0.1);
  const Eigen::Vector3d plain = PredictPose(pose, increment, 0.2);
  const Eigen::Vector3d skidded = PredictPose(pose, increment, 0.2, nullptr, nullptr, 0.05);
  const Eigen::Vector2d shift = (skidded - plain).head<2>();
  EXPECT_NEAR(shift.x(), 1.5e-3 * std::sin(0.05), 1e-15);
  EXPECT_NEAR(shift.y(), -1.5e-3 * std::cos(0.05), 1e-15);
  EXPECT_EQ(skidded.z(), plain.z());
  // A right turn skids to the left; no turn or no distance, no skid.
  const Eigen::Vector3d right = PredictPose(pose, Eigen::Vector2d(0.3, -0.1), 0.2, nullptr, nullptr, 0.05);
  const Eigen::Vector3d right_plain = PredictPose(pose, Eigen::Vector2d(0.3, -0.1), 0.2);
  EXPECT_GT(right.y() - right_plain.y(), 1e-3);
  EXPECT_EQ(PredictPose(pose, Eigen::Vector2d(0.3, 0.0), 0.2, nullptr, nullptr, 0.05),
            PredictPose(pose, Eigen::Vector2d(0.3, 0.0), 0.2));
  EXPECT_EQ(PredictPose(pose, Eigen::Vector2d(0.0, 0.1), 0.2, nullptr, nullptr, 0.05),
            PredictPose(pose, Eigen::Vector2d(0.0, 0.1), 0.2));
}

TEST(MotionModelTest, EulerIsThePapersEquationSixWithTheStartHeading) {
  // Heading pi/2, d = 0.3, dth = 0.1, a = 0.2: x' = x + d cos th - a dth sin th
  // = 1 - 0.02, y' = y + d sin th + a dth cos th = 2.3, th' = th + 0.1.
  const Eigen::Vector3d pose(1.0, 2.0, kPi / 2.0);
  const Eigen::Vector2d increment(0.3, 0.1);
  const Eigen::Vector3d euler =
      PredictPose(pose, increment, 0.2, nullptr, nullptr, 0.0, MotionIntegration::kEuler);
  EXPECT_NEAR(euler.x(), 1.0 - 0.02, 1e-12);
  EXPECT_NEAR(euler.y(), 2.3, 1e-12);
  EXPECT_NEAR(euler.z(), kPi / 2.0 + 0.1, 1e-12);
  // The exact arc ends elsewhere in a turn (by about d dth / 2 sideways)...
  const Eigen::Vector3d exact = PredictPose(pose, increment, 0.2);
  EXPECT_GT((exact - euler).head<2>().norm(), 0.01);
  // ... and at the same place without a turn.
  const Eigen::Vector2d straight(0.3, 0.0);
  EXPECT_LT((PredictPose(pose, straight, 0.2, nullptr, nullptr, 0.0, MotionIntegration::kEuler) -
             PredictPose(pose, straight, 0.2))
                .norm(),
            1e-15);
  // The skid moves R outward across the start heading: heading pi/2, left
  // turn, so +x by skid d dth.
  const Eigen::Vector3d skidded =
      PredictPose(pose, increment, 0.2, nullptr, nullptr, 0.05, MotionIntegration::kEuler);
  EXPECT_NEAR(skidded.x() - euler.x(), 0.05 * 0.3 * 0.1, 1e-15);
  EXPECT_NEAR(skidded.y(), euler.y(), 1e-15);
}

TEST(MotionModelTest, JacobiansAAndWMatchCentralDifferences) {
  // Both integrations, each with its own A and W.
  for (const MotionIntegration integration :
       {MotionIntegration::kExact, MotionIntegration::kEuler}) {
    SCOPED_TRACE(integration == MotionIntegration::kEuler ? "euler" : "exact");
    Rng rng(16);
    for (int trial = 0; trial < 100; ++trial) {
      const Eigen::Vector3d pose = RandomPose(&rng);
      const Eigen::Vector2d increment(rng.Gaussian(0.0, 0.5), rng.Gaussian(0.0, 0.5));
      const double a = 0.05 + 0.3 * rng.Uniform();
      const double skid = trial % 2 == 0 ? 0.0 : 0.2 * rng.Uniform();  // with and without
      Eigen::Matrix3d A;
      Eigen::Matrix<double, 3, 2> W;
      PredictPose(pose, increment, a, &A, &W, skid, integration);
      const Eigen::Matrix3d numerical_A = NumericalJacobian<3, 3>(
          [&](const Eigen::Vector3d& p) {
            return PredictPose(p, increment, a, nullptr, nullptr, skid, integration);
          },
          pose, {2});
      const Eigen::Matrix<double, 3, 2> numerical_W = NumericalJacobian<3, 2>(
          [&](const Eigen::Vector2d& u) {
            return PredictPose(pose, u, a, nullptr, nullptr, skid, integration);
          },
          increment, {2});
      EXPECT_LT((A - numerical_A).cwiseAbs().maxCoeff(), kJacobianTolerance) << "trial " << trial;
      EXPECT_LT((W - numerical_W).cwiseAbs().maxCoeff(), kJacobianTolerance) << "trial " << trial;
      // The two models' W differ in a turn: each test checks its own.
      const MotionIntegration other = integration == MotionIntegration::kEuler
                                          ? MotionIntegration::kExact
                                          : MotionIntegration::kEuler;
      Eigen::Matrix<double, 3, 2> W_other;
      PredictPose(pose, increment, a, nullptr, &W_other, skid, other);
      if (std::abs(increment.y()) > 0.1) {
        EXPECT_GT((W - W_other).cwiseAbs().maxCoeff(), 1e-3) << "trial " << trial;
      }
    }
  }
}

// The command noise of the CommandInput tests: 0.02 m/s + 10 %, 0.01 rad/s +
// 20 %, half the command's change.
CommandNoiseParams TestCommandNoise() {
  CommandNoiseParams noise;
  noise.v_std_mps = 0.02;
  noise.v_fraction = 0.1;
  noise.w_std_radps = 0.01;
  noise.w_fraction = 0.2;
  noise.change_fraction = 0.5;
  return noise;
}

TEST(MotionModelTest, CommandInputScalesWithDt) {
  CommandNoiseParams noise = TestCommandNoise();
  const MotionInput input = CommandInput(Twist2{0.5, -0.4}, 0.2, noise, Twist2{0.5, -0.4});
  EXPECT_NEAR(input.increment.x(), 0.1, 1e-12);
  EXPECT_NEAR(input.increment.y(), -0.08, 1e-12);
  EXPECT_NEAR(std::sqrt(input.covariance(0, 0)), 0.2 * (0.02 + 0.05), 1e-12);
  EXPECT_NEAR(std::sqrt(input.covariance(1, 1)), 0.2 * (0.01 + 0.08), 1e-12);
  EXPECT_EQ(input.covariance(0, 1), 0.0);
  // A step in the command from the previous record widens the noise by half
  // the step: v from 0.3 (0.2 more), w from 0.8 (1.2 more).
  const MotionInput step = CommandInput(Twist2{0.5, -0.4}, 0.2, noise, Twist2{0.3, 0.8});
  EXPECT_NEAR(std::sqrt(step.covariance(0, 0)), 0.2 * (0.02 + 0.05 + 0.1), 1e-12);
  EXPECT_NEAR(std::sqrt(step.covariance(1, 1)), 0.2 * (0.01 + 0.08 + 0.6), 1e-12);
  // No time, no motion, no noise.
  const MotionInput still = CommandInput(Twist2{0.5, -0.4}, 0.0, noise, Twist2{});
  EXPECT_EQ(still.increment.norm(), 0.0);
  EXPECT_EQ(still.covariance.norm(), 0.0);
}

TEST(MotionModelTest, OdometryInputIsTheIncrementInThePreviousFrame) {
  OdometryNoiseParams noise;
  // From (1, 1, pi/2), an arc of 0.3 m turning by 0.2 (a = 0.2): the input
  // that PredictPose turns back into the same motion.
  const Pose2 previous(1.0, 1.0, kPi / 2.0);
  const Eigen::Vector3d step = PredictPose(Eigen::Vector3d::Zero(), Eigen::Vector2d(0.3, 0.2), 0.2);
  const Pose2 current = previous * Pose2(step.x(), step.y(), step.z());
  const MotionInput input = OdometryInput(previous, current, 0.2, noise);
  EXPECT_NEAR(input.increment.x(), 0.3, 1e-12);
  EXPECT_NEAR(input.increment.y(), 0.2, 1e-12);
  const double variance_d = std::pow(noise.distance_std_m, 2) +
                            std::pow(noise.distance_std_m_per_sqrt_m, 2) * 0.3;
  const double variance_th = std::pow(noise.heading_std_rad, 2) +
                             std::pow(noise.heading_std_rad_per_sqrt_m, 2) * 0.3 +
                             std::pow(noise.heading_std_rad_per_sqrt_rad, 2) * 0.2;
  EXPECT_NEAR(input.covariance(0, 0), variance_d, 1e-15);
  EXPECT_NEAR(input.covariance(1, 1), variance_th, 1e-15);
  // Random walk: two records of half the motion add up to the same variance
  // as one (up to the per-record floors).
  OdometryNoiseParams no_floor = noise;
  no_floor.distance_std_m = 0.0;
  no_floor.heading_std_rad = 0.0;
  const auto arc = [](const Pose2& from, double d, double dth) {
    const Eigen::Vector3d step = PredictPose(Eigen::Vector3d::Zero(), Eigen::Vector2d(d, dth), 0.2);
    return from * Pose2(step.x(), step.y(), step.z());
  };
  const Pose2 half = arc(previous, 0.15, 0.1);
  const Eigen::Matrix2d one = OdometryInput(previous, arc(previous, 0.3, 0.2), 0.2, no_floor).covariance;
  const Eigen::Matrix2d two = OdometryInput(previous, half, 0.2, no_floor).covariance +
                              OdometryInput(half, arc(half, 0.15, 0.1), 0.2, no_floor).covariance;
  EXPECT_NEAR((one - two).norm(), 0.0, 1e-14);
  // The heading increment is wrapped across +-pi.
  const MotionInput across = OdometryInput(Pose2(0, 0, 3.1), Pose2(0, 0, -3.1), 0.2, noise);
  EXPECT_NEAR(across.increment.y(), 2.0 * kPi - 6.2, 1e-12);
}

}  // namespace
}  // namespace mjslam::slam
