// The sparse filter operations of SlamState against dense reference
// computations: prediction, augmentation, sequential correction; and P's
// symmetry and positive semi-definiteness over long random runs.

#include "slam/slam_state.h"

#include <cmath>
#include <vector>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/rng.h"
#include "slam/corrections.h"
#include "slam/motion_model.h"
#include "slam/observation_models.h"
#include "tests/slam/ekf_test_utils.h"

namespace mjslam::slam {
namespace {

using testing::MinEigenvalue;
using testing::RandomCovariance2;

const Pose2 kMount(0.12, -0.03, 0.05);
constexpr double kA = 0.15;

// A state with `num_features` features around the robot, made correlated by
// a few predictions and corrections.
SlamState MakeState(Rng* rng, int num_features) {
  Eigen::Matrix3d P0 = Eigen::Vector3d(0.01, 0.02, 0.001).asDiagonal();
  SlamState state(Eigen::Vector3d(0.5, -0.3, 0.4), P0, kMount);
  for (int k = 0; k < num_features; ++k) {
    const bool line = k % 2 == 0;
    const Eigen::Vector2d z(1.0 + 4.0 * rng->Uniform(), kPi * (2.0 * rng->Uniform() - 1.0));
    state.AddFeature(line ? FeatureType::kLine : FeatureType::kCorner, z,
                     RandomCovariance2(rng, 0.02, 0.02));
    MotionInput input;
    input.increment = Eigen::Vector2d(0.05, 0.02);
    input.covariance = Eigen::Vector2d(1e-4, 1e-4).asDiagonal();
    state.Predict(input, kA);
    if (k > 0) {
      const int j = k - 1;
      const Eigen::Vector2d h = state.Measure(j).h;
      state.Update(j, h + Eigen::Vector2d(0.01, 0.005), RandomCovariance2(rng, 0.02, 0.02));
    }
  }
  return state;
}

// Dense H (2 x n) of an observation z of feature k.
Eigen::MatrixXd DenseH(const SlamState& state, int k, const Eigen::Vector2d& z) {
  const SlamState::Measurement m = state.MeasureFor(k, z);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(2, state.dimension());
  H.leftCols<3>() = m.H_pose;
  H.middleCols<2>(state.FeatureIndex(k)) = m.H_feature;
  return H;
}

// One dense EKF correction in Joseph form, the reference for Update.
void DenseUpdate(const SlamState& state, int k, const Eigen::Vector2d& z,
                 const Eigen::Matrix2d& R, Eigen::VectorXd* x, Eigen::MatrixXd* P) {
  const Eigen::MatrixXd H = DenseH(state, k, z);
  const Eigen::Vector2d nu = Innovation(z, state.MeasureFor(k, z).h);
  const Eigen::Matrix2d S = H * (*P) * H.transpose() + R;
  const Eigen::MatrixXd K = (*P) * H.transpose() * S.inverse();
  *x += K * nu;
  const Eigen::MatrixXd I_KH = Eigen::MatrixXd::Identity(x->size(), x->size()) - K * H;
  *P = I_KH * (*P) * I_KH.transpose() + K * R * K.transpose();
}

TEST(SlamStateTest, PredictionEqualsDenseAPAtPlusWQWt) {
  Rng rng(21);
  SlamState state = MakeState(&rng, 6);
  const Eigen::MatrixXd P = state.covariance();
  const Eigen::VectorXd x = state.mean();
  const int n = state.dimension();

  MotionInput input;
  input.increment = Eigen::Vector2d(0.2, -0.15);
  input.covariance << 4e-4, 1e-5, 1e-5, 9e-4;
  Eigen::Matrix3d A;
  Eigen::Matrix<double, 3, 2> W;
  PredictPose(x.head<3>(), input.increment, kA, &A, &W);
  Eigen::MatrixXd A_full = Eigen::MatrixXd::Identity(n, n);
  A_full.topLeftCorner<3, 3>() = A;
  Eigen::MatrixXd W_full = Eigen::MatrixXd::Zero(n, 2);
  W_full.topRows<3>() = W;
  const Eigen::MatrixXd expected =
      A_full * P * A_full.transpose() + W_full * input.covariance * W_full.transpose();

  state.Predict(input, kA);
  EXPECT_LT((state.covariance() - expected).cwiseAbs().maxCoeff(), 1e-15);
  // Only the pose rows and columns changed: the map block is bit-identical.
  EXPECT_TRUE((state.covariance().bottomRightCorner(n - 3, n - 3).array() ==
               P.bottomRightCorner(n - 3, n - 3).array())
                  .all());
  EXPECT_TRUE((state.mean().tail(n - 3).array() == x.tail(n - 3).array()).all());
  EXPECT_LT((state.pose() - PredictPose(x.head<3>(), input.increment, kA)).norm(), 1e-15);
}

TEST(SlamStateTest, LateralSlipAddsVarianceAcrossTheMidArcHeadingOnly) {
  Rng rng(23);
  SlamState with_slip = MakeState(&rng, 4);
  SlamState without = with_slip;
  const double th0 = with_slip.pose().z();
  MotionInput input;
  input.increment = Eigen::Vector2d(0.05, 0.3);
  input.covariance << 4e-4, 0.0, 0.0, 9e-4;
  without.Predict(input, kA);
  input.lateral_variance_m2 = 2.5e-5;
  with_slip.Predict(input, kA);

  // The difference is s^2 n n^T in the position block, n across th0 + 0.15.
  const Eigen::Vector2d n(-std::sin(th0 + 0.15), std::cos(th0 + 0.15));
  const Eigen::MatrixXd difference = with_slip.covariance() - without.covariance();
  EXPECT_LT((difference.topLeftCorner<2, 2>() - 2.5e-5 * n * n.transpose()).cwiseAbs().maxCoeff(),
            1e-15);
  Eigen::MatrixXd rest = difference;
  rest.topLeftCorner<2, 2>().setZero();
  EXPECT_EQ(rest.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((with_slip.mean() - without.mean()).cwiseAbs().maxCoeff(), 0.0);
}

TEST(SlamStateTest, AugmentationEqualsDenseComputation) {
  Rng rng(22);
  for (const FeatureType type : {FeatureType::kLine, FeatureType::kCorner}) {
    SlamState state = MakeState(&rng, 5);
    const Eigen::MatrixXd P = state.covariance();
    const int n = state.dimension();
    const Eigen::Vector2d z(2.5, 0.7);
    const Eigen::Matrix2d R = RandomCovariance2(&rng, 0.03, 0.01);

    // Brute force: xi' = [xi; g(pose, z)], P' = J P J^T + M R M^T with
    // J = [I; G_pose 0] and M = [0; G_z].
    Eigen::Matrix<double, 2, 3> G_pose;
    Eigen::Matrix2d G_z;
    const Eigen::Vector2d f = InitializeFeature(type, state.pose(), z, kMount, &G_pose, &G_z);
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(n + 2, n);
    J.topRows(n).setIdentity();
    J.block<2, 3>(n, 0) = G_pose;
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 2, 2);
    M.bottomRows<2>() = G_z;
    const Eigen::MatrixXd expected = J * P * J.transpose() + M * R * M.transpose();

    const int k = state.AddFeature(type, z, R);
    EXPECT_EQ(k, 5);
    EXPECT_EQ(state.feature_type(k), type);
    EXPECT_EQ(state.dimension(), n + 2);
    EXPECT_LT((state.feature(k) - f).norm(), 1e-15);
    EXPECT_LT((state.covariance() - expected).cwiseAbs().maxCoeff(), 1e-15);
  }
}

// Where the lines (r, al) a and b meet, solved by Eigen's LU, for the
// reference below.
Eigen::Vector2d MeetingPoint(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  Eigen::Matrix2d normals;
  normals << std::cos(a.y()), std::sin(a.y()), std::cos(b.y()), std::sin(b.y());
  return normals.partialPivLu().solve(Eigen::Vector2d(a.x(), b.x()));
}

// A corner placed where two map lines meet is a function of the state:
// xi' = [xi; c(f_a, f_b)], P' = G P G^T with G = [I; dc/dxi], dc/dxi here by
// central differences. The corner is correlated with its lines and, through
// them, with the pose.
TEST(SlamStateTest, LineIntersectionEqualsDenseComputation) {
  Rng rng(24);
  for (int trial = 0; trial < 10; ++trial) {
    SlamState state = MakeState(&rng, 6);
    const int a = 2 * (trial % 3);        // lines are the even features
    const int b = 2 * ((trial + 1) % 3);
    const Eigen::MatrixXd P = state.covariance();
    const int n = state.dimension();
    const Eigen::Vector2d c = MeetingPoint(state.feature(a), state.feature(b));

    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n + 2, n);
    G.topRows(n).setIdentity();
    const double step = 1e-6;
    for (int i = 0; i < 4; ++i) {
      const int column = state.FeatureIndex(i < 2 ? a : b) + i % 2;
      Eigen::Vector2d fa_plus = state.feature(a), fa_minus = state.feature(a);
      Eigen::Vector2d fb_plus = state.feature(b), fb_minus = state.feature(b);
      Eigen::Vector2d& plus = i < 2 ? fa_plus : fb_plus;
      Eigen::Vector2d& minus = i < 2 ? fa_minus : fb_minus;
      plus(i % 2) += step;
      minus(i % 2) -= step;
      G.block<2, 1>(n, column) =
          (MeetingPoint(fa_plus, fb_plus) - MeetingPoint(fa_minus, fb_minus)) / (2.0 * step);
    }
    const Eigen::MatrixXd expected = G * P * G.transpose();

    const int k = state.AddLineIntersection(a, b);
    EXPECT_EQ(k, 6);
    EXPECT_EQ(state.feature_type(k), FeatureType::kCorner);
    EXPECT_EQ(state.dimension(), n + 2);
    EXPECT_LT((state.feature(k) - c).norm(), 1e-9) << "trial " << trial;
    // Central differences are good to about 1e-8 relative here.
    EXPECT_LT((state.covariance() - expected).cwiseAbs().maxCoeff(),
              1e-7 * expected.cwiseAbs().maxCoeff())
        << "trial " << trial;
    EXPECT_EQ(state.covariance(), state.covariance().transpose());
    // The corner's block is as uncertain as its lines make it, not zero, and
    // it is correlated with line a.
    EXPECT_GT(state.feature_covariance(k).trace(), 0.0);
    const Eigen::Matrix2d corner_line_a =
        state.covariance().block<2, 2>(state.FeatureIndex(k), state.FeatureIndex(a));
    EXPECT_GT(corner_line_a.cwiseAbs().maxCoeff(), 0.0);
  }
}

TEST(SlamStateTest, UpdateEqualsDenseReferenceEkf) {
  Rng rng(23);
  for (int trial = 0; trial < 20; ++trial) {
    SlamState state = MakeState(&rng, 4);
    const int k = trial % 4;
    const Eigen::Matrix2d R = RandomCovariance2(&rng, 0.05, 0.03);
    const Eigen::Vector2d z =
        state.Measure(k).h + Eigen::Vector2d(rng.Gaussian(0.0, 0.05), rng.Gaussian(0.0, 0.03));
    Eigen::VectorXd x = state.mean();
    Eigen::MatrixXd P = state.covariance();
    DenseUpdate(state, k, z, R, &x, &P);

    state.Update(k, z, R);
    Eigen::VectorXd difference = state.mean() - x;
    for (int i = 2; i < state.dimension(); ++i) {
      const bool angle = i == 2 || (i >= 3 && (i - 3) % 2 == 1 &&
                                    state.feature_type((i - 3) / 2) == FeatureType::kLine);
      if (angle) difference(i) = WrapAngle(difference(i));
    }
    EXPECT_LT(difference.cwiseAbs().maxCoeff(), 1e-12) << "trial " << trial;
    EXPECT_LT((state.covariance() - P).cwiseAbs().maxCoeff(), 1e-12) << "trial " << trial;
  }
}

TEST(SlamStateTest, ClassicalCorrectionEqualsDenseSequentialEkf) {
  // Algorithm 1 over three matched features, each re-linearised at the
  // current mean, against the dense EKF doing the same.
  Rng rng(24);
  SlamState state = MakeState(&rng, 6);
  std::vector<MatchedObservation> matched;
  for (const int k : {4, 1, 2}) {
    const Eigen::Vector2d z =
        state.Measure(k).h + Eigen::Vector2d(rng.Gaussian(0.0, 0.03), rng.Gaussian(0.0, 0.02));
    matched.push_back({k, z, RandomCovariance2(&rng, 0.03, 0.02)});
  }
  SlamState reference = state;
  Eigen::VectorXd x = reference.mean();
  Eigen::MatrixXd P = reference.covariance();
  for (const MatchedObservation& observation : matched) {
    // The dense update at the state the sparse one would linearise at.
    DenseUpdate(reference, observation.feature, observation.z, observation.R, &x, &P);
    reference.Update(observation.feature, observation.z, observation.R);
  }
  EXPECT_EQ(CorrectClassical(&state, matched), 3);
  EXPECT_LT((state.mean() - x).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((state.covariance() - P).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(SlamStateTest, CovarianceStaysExactlySymmetricAndPsdOverLongRandomRuns) {
  // 3000 random steps: predictions, corrections of random features with
  // observations near their predictions, and new features up to 60.
  const std::uint64_t seed = 25;
  Rng rng(seed);
  SlamState state(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero(), kMount);
  int checks = 0;
  for (int step = 0; step < 3000; ++step) {
    MotionInput input;
    input.increment = Eigen::Vector2d(rng.Gaussian(0.05, 0.05), rng.Gaussian(0.0, 0.05));
    input.covariance = Eigen::Vector2d(1e-4, 4e-4).asDiagonal();
    state.Predict(input, kA);
    if (state.num_features() < 60 && rng.Bernoulli(0.1)) {
      const Eigen::Vector2d z(1.0 + 5.0 * rng.Uniform(), kPi * (2.0 * rng.Uniform() - 1.0));
      state.AddFeature(rng.Bernoulli(0.5) ? FeatureType::kLine : FeatureType::kCorner, z,
                       RandomCovariance2(&rng, 0.01, 0.005));
    }
    for (int u = 0; u < 5 && state.num_features() > 0; ++u) {
      const int k = static_cast<int>(rng.Uniform() * state.num_features());
      const SlamState::Measurement m = state.Measure(k);
      if (!m.valid) continue;
      const Eigen::Vector2d z = m.h + Eigen::Vector2d(rng.Gaussian(0.0, 0.01), rng.Gaussian(0.0, 0.005));
      state.Update(k, z, RandomCovariance2(&rng, 0.01, 0.005));
    }
    if (step % 250 == 249) {
      const Eigen::MatrixXd P = state.covariance();
      // Exactly symmetric, bit for bit.
      EXPECT_TRUE((P.array() == P.transpose().array()).all()) << "seed " << seed << " step " << step;
      EXPECT_GE(MinEigenvalue(P), -1e-12 * P.diagonal().maxCoeff())
          << "seed " << seed << " step " << step;
      EXPECT_GT(P.diagonal().minCoeff(), 0.0) << "seed " << seed << " step " << step;
      ++checks;
    }
  }
  EXPECT_EQ(checks, 12);
  EXPECT_EQ(state.num_features(), 60);
  // Angles stayed wrapped.
  EXPECT_LE(std::abs(state.pose().z()), kPi);
  for (int k = 0; k < state.num_features(); ++k) {
    if (state.feature_type(k) == FeatureType::kLine) {
      EXPECT_LE(std::abs(state.feature(k).y()), kPi);
    }
  }
}

// Removing a feature leaves exactly the marginal of the rest: the mean and P
// with that feature's entries deleted, bit for bit; a feature added after it
// is augmented as if the removed one had never been there.
TEST(SlamStateTest, RemovingAFeatureLeavesTheMarginalOfTheRest) {
  for (const JacobianPoint jacobians : {JacobianPoint::kCurrent, JacobianPoint::kFirstEstimates}) {
    Rng rng(31);
    SlamState state = MakeState(&rng, 7);
    if (jacobians == JacobianPoint::kFirstEstimates) {
      SlamState fej(state.pose(), state.pose_covariance(), kMount, jacobians);
      for (int k = 0; k < 7; ++k) {
        fej.AddFeature(state.feature_type(k), state.Measure(k).h, RandomCovariance2(&rng, 0.02, 0.02));
      }
      state = fej;
    }
    for (const int k : {6, 2, 0}) {  // the last, a middle and the first feature
      const Eigen::VectorXd x = state.mean();
      const Eigen::VectorXd x_lin = state.linearization_point();
      const Eigen::MatrixXd P = state.covariance();
      const int n = state.dimension();
      const int j = state.FeatureIndex(k);
      std::vector<int> keep;
      for (int i = 0; i < n; ++i) {
        if (i != j && i != j + 1) keep.push_back(i);
      }
      const FeatureType after = k + 1 < state.num_features() ? state.feature_type(k + 1)
                                                              : FeatureType::kLine;
      state.RemoveFeature(k);
      ASSERT_EQ(state.dimension(), n - 2);
      for (int r = 0; r < n - 2; ++r) {
        EXPECT_EQ(state.mean()[r], x[keep[r]]) << r;
        EXPECT_EQ(state.linearization_point()[r], x_lin[keep[r]]) << r;
        for (int c = 0; c < n - 2; ++c) {
          EXPECT_EQ(state.covariance()(r, c), P(keep[r], keep[c])) << r << " " << c;
        }
      }
      if (k + 1 < n / 2) EXPECT_EQ(state.feature_type(k), after);
    }
    // An augmentation after the removals: the new rows are G_pose P_pose,x,
    // and nothing stale from the freed entries shows.
    const Eigen::MatrixXd P = state.covariance();
    const int k = state.AddFeature(FeatureType::kCorner, Eigen::Vector2d(2.0, 0.3),
                                   Eigen::Matrix2d::Identity() * 1e-4);
    const Eigen::MatrixXd P_new = state.covariance();
    EXPECT_TRUE(P_new.topLeftCorner(P.rows(), P.cols()).isApprox(P, 0.0));
    const Eigen::MatrixXd cross = P_new.block(state.FeatureIndex(k), 0, 2, P.cols());
    const Eigen::MatrixXd G_pose = cross.leftCols<3>() * P.topLeftCorner<3, 3>().inverse();
    EXPECT_TRUE(cross.isApprox(G_pose * P.topRows<3>(), 1e-9));
  }
}

TEST(SlamStateTest, BufferGrowsGeometricallyAndKeepsP) {
  Rng rng(26);
  SlamState state(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity() * 1e-4, kMount);
  int growths = 0;
  int capacity = state.capacity();
  EXPECT_EQ(capacity % 8, 0);
  Eigen::MatrixXd before;
  for (int k = 0; k < 300; ++k) {
    // The old block is unchanged by the augmentation, when the buffer grows
    // and (sampled) when it does not.
    const bool check = state.dimension() + 2 > state.capacity() || k % 25 == 0;
    if (check) before = state.covariance();
    state.AddFeature(FeatureType::kCorner, Eigen::Vector2d(2.0 + rng.Uniform(), rng.Uniform()),
                     Eigen::Matrix2d::Identity() * 1e-4);
    if (check) {
      ASSERT_TRUE((state.covariance().topLeftCorner(before.rows(), before.cols()).array() ==
                   before.array())
                      .all())
          << "feature " << k;
    }
    if (state.capacity() != capacity) {
      ++growths;
      EXPECT_GE(state.capacity(), 2 * capacity);
      EXPECT_EQ(state.capacity() % 8, 0);
      capacity = state.capacity();
    }
  }
  // 603 entries from an initial 40: 40 -> 80 -> 160 -> 320 -> 640.
  EXPECT_LE(growths, 5);
  EXPECT_GE(state.capacity(), state.dimension());
}

}  // namespace
}  // namespace mjslam::slam

namespace mjslam::slam {
namespace {

TEST(SlamStateTest, LineCorrectionIsContinuousWhenTheSensorCrossesTheLine) {
  // The wall y = 1 (r = 1, al = pi/2) mapped from (0, 0.5) facing +y; the
  // robot then drives 0.49 m with uncertain distance: estimated 1 cm before
  // the line while the sensor really is 1 cm past it. The canonical forms
  // differ by pi in alpha, but the aligned innovation is 2 cm in rho.
  SlamState state(Eigen::Vector3d(0.0, 0.5, kPi / 2.0), Eigen::Matrix3d::Identity() * 1e-10,
                  Pose2());
  const int k = state.AddFeature(FeatureType::kLine, Eigen::Vector2d(0.5, 0.0),
                                 Eigen::Vector2d(1e-8, 1e-8).asDiagonal());
  EXPECT_NEAR(state.feature(k).x(), 1.0, 1e-12);
  EXPECT_NEAR(state.feature(k).y(), kPi / 2.0, 1e-12);
  MotionInput input;
  input.increment = Eigen::Vector2d(0.49, 0.0);
  input.covariance = Eigen::Vector2d(1e-4, 1e-10).asDiagonal();
  state.Predict(input, 0.0);
  const SlamState::Measurement canonical = state.Measure(k);
  EXPECT_NEAR(canonical.h.x(), 0.01, 1e-12);  // 1 cm ahead
  EXPECT_NEAR(canonical.h.y(), 0.0, 1e-12);
  // Observed from 1 cm past the line: rho = 0.01, alpha = pi (behind).
  const Eigen::Vector2d z(0.01, kPi);
  const SlamState::Measurement aligned = state.MeasureFor(k, z);
  EXPECT_NEAR(aligned.h.x(), -0.01, 1e-12);
  EXPECT_NEAR(WrapAngle(aligned.h.y() - z.y()), 0.0, 1e-12);
  EXPECT_NEAR(Innovation(z, aligned.h).x(), 0.02, 1e-12);
  // The aligned Jacobian is the derivative of the aligned branch.
  const Eigen::Matrix<double, 2, 3> numerical = testing::NumericalJacobian<2, 3>(
      [&](const Eigen::Vector3d& pose) {
        Eigen::Vector2d h = PredictLine(pose, state.feature(k), Pose2());
        AlignLineToObservation(z, &h);
        return h;
      },
      state.pose(), {1}, 1e-4);
  EXPECT_LT((aligned.H_pose - numerical).cwiseAbs().maxCoeff(), 1e-6);
  // The correction moves the robot forward by nearly the 2 cm (the distance
  // was the uncertain part), and the heading barely moves.
  const Eigen::Vector3d before = state.pose();
  state.Update(k, z, Eigen::Vector2d(1e-6, 1e-6).asDiagonal());
  EXPECT_GT(state.pose().y() - before.y(), 0.018);
  EXPECT_LT(state.pose().y() - before.y(), 0.0201);
  EXPECT_LT(std::abs(WrapAngle(state.pose().z() - before.z())), 1e-6);
}

}  // namespace
}  // namespace mjslam::slam
