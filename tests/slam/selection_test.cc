// The paper's selection criterion (Algorithm 2, Eq. 15): the closed form
// against an eigen-solver, Theorem 3 on a small state, and the selective
// correction's choices.

#include "slam/corrections.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/rng.h"
#include "slam/motion_model.h"
#include "slam/slam_state.h"
#include "tests/slam/ekf_test_utils.h"

namespace mjslam::slam {
namespace {

using testing::RandomCovariance2;
using testing::RandomSpd;
using Matrix5d = Eigen::Matrix<double, 5, 5>;

// Real parts of the eigenvalues of a general matrix, sorted; fails the test
// if any imaginary part is not negligible.
std::vector<double> SortedRealEigenvalues(const Eigen::MatrixXd& M) {
  Eigen::EigenSolver<Eigen::MatrixXd> solver(M, /*computeEigenvectors=*/false);
  std::vector<double> values;
  for (Eigen::Index i = 0; i < M.rows(); ++i) {
    const std::complex<double> value = solver.eigenvalues()(i);
    EXPECT_LT(std::abs(value.imag()), 1e-9);
    values.push_back(value.real());
  }
  std::sort(values.begin(), values.end());
  return values;
}

// The criterion the brute-force way: sum of the eigenvalues of B_i.
double EigenSolverCriterion(const SlamState& state, const MatchedObservation& observation) {
  const SlamState::Measurement m = state.MeasureFor(observation.feature, observation.z);
  Eigen::Matrix<double, 2, 5> H;
  H << m.H_pose, m.H_feature;
  const Matrix5d B = SelectionBlock(state.JointCovariance(observation.feature), H, observation.R);
  double sum = 0.0;
  for (const double value : SortedRealEigenvalues(B)) sum += value;
  return sum;
}

TEST(SelectionTest, ClosedFormEqualsEigenSolverSumOnRandomSpdInputs) {
  const std::uint64_t seed = 31;
  Rng rng(seed);
  for (int trial = 0; trial < 300; ++trial) {
    // Spread conditioning: eigenvalues of P_b over up to 4 decades.
    const double low = std::pow(10.0, -4.0 * rng.Uniform());
    const Matrix5d P_b = RandomSpd(&rng, 5, 1e-4 * low, 1.0);
    Eigen::Matrix<double, 2, 5> H;
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 5; ++j) H(i, j) = rng.Gaussian(0.0, 1.0);
    }
    const Eigen::Matrix2d R = RandomSpd(&rng, 2, 1e-4, 1e-1);

    const Matrix5d B = SelectionBlock(P_b, H, R);
    const std::vector<double> eigenvalues = SortedRealEigenvalues(B);
    double eigen_sum = 0.0;
    for (const double value : eigenvalues) eigen_sum += value;

    const Eigen::Matrix2d S = H * P_b * H.transpose() + R;
    const double closed_form = SelectionCriterion(S, R);
    EXPECT_NEAR(closed_form, eigen_sum, 1e-8) << "seed " << seed << " trial " << trial;
    // = 5 - trace(K H) = 3 + trace(S^-1 R), in (3, 5].
    EXPECT_NEAR(closed_form, 5.0 - (Matrix5d::Identity() - B).trace(), 1e-8);
    EXPECT_GT(closed_form, 3.0);
    EXPECT_LE(closed_form, 5.0 + 1e-12);
    // Three eigenvalues are 1; the other two are those of S^-1 R.
    const std::vector<double> expected_small = SortedRealEigenvalues(S.inverse() * R);
    std::vector<double> expected = {1.0, 1.0, 1.0, expected_small[0], expected_small[1]};
    std::sort(expected.begin(), expected.end());
    for (int i = 0; i < 5; ++i) EXPECT_NEAR(eigenvalues[i], expected[i], 1e-8);
    // det B = det R / det S.
    EXPECT_NEAR(B.determinant(), R.determinant() / S.determinant(), 1e-8);
  }
}

TEST(SelectionTest, TheoremThreeBlockEigenvaluesAreASubsetOfTheFullOnes) {
  // On a state of 3 + 2 * 4 = 11 entries: the eigenvalues of the full
  // I - K H are those of the 5x5 block B_i plus n - 5 ones.
  const std::uint64_t seed = 32;
  Rng rng(seed);
  const int n = 11;
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::MatrixXd P = RandomSpd(&rng, n, 1e-3, 1.0);
    const int feature = trial % 4;
    const int j = 3 + 2 * feature;  // the state index of the feature (no self-calibration)
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(2, n);
    for (int i = 0; i < 2; ++i) {
      for (const int col : {0, 1, 2, j, j + 1}) H(i, col) = rng.Gaussian(0.0, 1.0);
    }
    const Eigen::Matrix2d R = RandomSpd(&rng, 2, 1e-3, 1e-1);
    const Eigen::Matrix2d S = H * P * H.transpose() + R;
    const Eigen::MatrixXd K = P * H.transpose() * S.inverse();
    const Eigen::MatrixXd full = Eigen::MatrixXd::Identity(n, n) - K * H;

    // B_i from the pose + feature rows and columns.
    const std::vector<int> block_indices = {0, 1, 2, j, j + 1};
    Matrix5d P_b;
    Eigen::Matrix<double, 2, 5> H_b;
    for (int a = 0; a < 5; ++a) {
      for (int b = 0; b < 5; ++b) P_b(a, b) = P(block_indices[a], block_indices[b]);
      H_b.col(a) = H.col(block_indices[a]);
    }
    const Matrix5d B = SelectionBlock(P_b, H_b, R);

    std::vector<double> expected = SortedRealEigenvalues(B);
    for (int i = 5; i < n; ++i) expected.push_back(1.0);
    std::sort(expected.begin(), expected.end());
    const std::vector<double> actual = SortedRealEigenvalues(full);
    ASSERT_EQ(actual.size(), expected.size());
    for (int i = 0; i < n; ++i) {
      EXPECT_NEAR(actual[i], expected[i], 1e-8) << "seed " << seed << " trial " << trial;
    }
    // The block of the full matrix is B_i itself.
    for (int a = 0; a < 5; ++a) {
      for (int b = 0; b < 5; ++b) {
        EXPECT_NEAR(full(block_indices[a], block_indices[b]), B(a, b), 1e-12);
      }
    }
  }
}

// A state with `num_features` corners and lines, added from poses a noisy
// motion apart, so that their errors relative to the robot are correlated
// (features added from one pose would be independent relative to it, and
// one correction would never reorder the others).
SlamState MakeState(Rng* rng, int num_features) {
  SlamState state(Eigen::Vector3d(0.0, 0.0, 0.2), Eigen::Vector3d(0.01, 0.01, 0.001).asDiagonal(),
                  Pose2(0.1, 0.0, 0.0));
  for (int k = 0; k < num_features; ++k) {
    const Eigen::Vector2d z(1.0 + 4.0 * rng->Uniform(), 2.0 * rng->Uniform() - 1.0);
    state.AddFeature(k % 3 == 0 ? FeatureType::kLine : FeatureType::kCorner, z,
                     RandomCovariance2(rng, 0.05, 0.03));
    MotionInput input;
    input.increment = Eigen::Vector2d(0.2, 0.1 * rng->Gaussian(0.0, 1.0));
    input.covariance = Eigen::Vector2d(0.01, 0.01).asDiagonal();
    state.Predict(input, 0.15);
  }
  return state;
}

std::vector<MatchedObservation> MakeMatched(Rng* rng, const SlamState& state, int count) {
  std::vector<MatchedObservation> matched;
  for (int k = 0; k < count; ++k) {
    // Measurement noise within a factor of 3: the criteria are close enough
    // that one correction (through the shared pose) can reorder them.
    const double scale = std::pow(3.0, -rng->Uniform());
    const Eigen::Matrix2d R = RandomCovariance2(rng, 0.1 * scale, 0.05 * scale);
    const Eigen::Vector2d z = state.Measure(k).h +
                              Eigen::Vector2d(rng->Gaussian(0.0, 0.01), rng->Gaussian(0.0, 0.005));
    matched.push_back({k, z, R});
  }
  return matched;
}

TEST(SelectionTest, SelectivePicksTheArgminWithTheCurrentCovarianceAndAtMostMax) {
  const std::uint64_t seed = 33;
  Rng rng(seed);
  int differs_from_static_ranking = 0;
  for (int trial = 0; trial < 100; ++trial) {
    SlamState state = MakeState(&rng, 8);
    const std::vector<MatchedObservation> matched = MakeMatched(&rng, state, 6);
    const int max_updates = 1 + trial % 3;

    // Reference: brute-force eigenvalue sums, recomputed after each update.
    SlamState reference = state;
    std::vector<int> remaining = {0, 1, 2, 3, 4, 5};
    std::vector<int> expected;
    std::vector<double> initial(6);
    for (int i = 0; i < 6; ++i) initial[i] = EigenSolverCriterion(state, matched[i]);
    for (int round = 0; round < max_updates; ++round) {
      int best = -1;
      double best_value = std::numeric_limits<double>::infinity();
      for (const int i : remaining) {
        const double value = EigenSolverCriterion(reference, matched[i]);
        if (value < best_value) {
          best_value = value;
          best = i;
        }
      }
      expected.push_back(best);
      reference.Update(matched[best].feature, matched[best].z, matched[best].R);
      remaining.erase(std::find(remaining.begin(), remaining.end(), best));
    }
    // Would ranking once with the initial P have chosen differently?
    std::vector<int> static_order = {0, 1, 2, 3, 4, 5};
    std::sort(static_order.begin(), static_order.end(),
              [&](int a, int b) { return initial[a] < initial[b]; });
    if (!std::equal(expected.begin(), expected.end(), static_order.begin())) {
      ++differs_from_static_ranking;
    }

    const std::vector<int> used = CorrectSelective(&state, matched, max_updates);
    EXPECT_EQ(used, expected) << "seed " << seed << " trial " << trial;
    EXPECT_EQ(static_cast<int>(used.size()), max_updates);
    EXPECT_LT((state.mean() - reference.mean()).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((state.covariance() - reference.covariance()).cwiseAbs().maxCoeff(), 1e-12);
  }
  // The criterion is recomputed with the current P: in some trials this
  // changes the choice, so the test tells the two apart.
  EXPECT_GT(differs_from_static_ranking, 0);
  std::printf("choices differing from a one-off ranking: %d of 100\n", differs_from_static_ranking);
}

TEST(SelectionTest, SelectiveUsesMinOfMatchedAndMax) {
  Rng rng(34);
  SlamState state = MakeState(&rng, 8);
  const std::vector<MatchedObservation> matched = MakeMatched(&rng, state, 3);
  // MAX above |M|: every candidate, each once.
  SlamState a = state;
  std::vector<int> used = CorrectSelective(&a, matched, 10);
  std::sort(used.begin(), used.end());
  EXPECT_EQ(used, (std::vector<int>{0, 1, 2}));
  // No candidates: nothing changes.
  SlamState b = state;
  EXPECT_TRUE(CorrectSelective(&b, {}, 2).empty());
  EXPECT_TRUE((b.mean().array() == state.mean().array()).all());
  // The classical correction uses all of them.
  SlamState c = state;
  EXPECT_EQ(CorrectClassical(&c, matched), 3);
}

// A hand-made selection problem whose answer is known. The pose is uncertain
// (x, y, th all, full rank); two corners are independent of it and of each
// other: corner A, 2 m ahead, barely known (1 m std), and corner B, 2 m to
// the left, almost exactly known. Candidates, in extraction order:
//   0: A with R = 1e-3 I   (informative by the criterion, no pose gain)
//   1: B with R = 1e-1 I   (little information: S is dominated by R)
//   2: A with R = 1e-4 I   (the smallest trace(S^-1 R): the criterion's pick)
//   3: B with R = 1e-2 I   (pins the pose: the smallest det of P_pp after)
// A's innovation is explained by A's own uncertainty, so observing it
// precisely lowers 3 + tr(S^-1 R) but leaves the pose as it was; B's
// corrects the pose.
struct KnownProblem {
  SlamState state;
  std::vector<MatchedObservation> matched;
};

KnownProblem MakeKnownProblem() {
  SlamState state(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero(), Pose2());
  const int a = state.AddFeature(FeatureType::kCorner, Eigen::Vector2d(2.0, 0.0),
                                 Eigen::Vector2d(1.0, 0.25).asDiagonal());
  const int b = state.AddFeature(FeatureType::kCorner, Eigen::Vector2d(2.0, kPi / 2.0),
                                 Eigen::Vector2d(1e-8, 1e-8).asDiagonal());
  MotionInput input;  // no motion, but the pose becomes uncertain
  input.covariance = Eigen::Vector2d(0.01, 0.01).asDiagonal();
  input.lateral_variance_m2 = 0.01;
  state.Predict(input, 0.2);
  KnownProblem problem{state, {}};
  const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
  auto observe = [&](int k, double r) {
    problem.matched.push_back({k, state.Measure(k).h + Eigen::Vector2d(0.01, 0.005), r * I});
  };
  observe(a, 1e-3);
  observe(b, 1e-1);
  observe(a, 1e-4);
  observe(b, 1e-2);
  return problem;
}

// The index chosen with MAX = 1 under `policy`.
int ChosenAlone(SelectionPolicy policy, Rng* rng = nullptr) {
  KnownProblem problem = MakeKnownProblem();
  const std::vector<int> used =
      CorrectSelective(&problem.state, problem.matched, 1, policy, rng);
  EXPECT_EQ(used.size(), 1u);
  return used.empty() ? -1 : used[0];
}

TEST(SelectionPolicyTest, TheKnownProblemIsAsDesigned) {
  // The premises of the expected answers below, so that a change of the
  // problem cannot make the policy tests pass by accident.
  const KnownProblem problem = MakeKnownProblem();
  EXPECT_GT(problem.state.pose_covariance().determinant(), 0.0);
  std::vector<double> criterion, determinant;
  for (const MatchedObservation& candidate : problem.matched) {
    criterion.push_back(SelectionCriterion(problem.state, candidate));
    determinant.push_back(PoseDeterminantAfter(problem.state, candidate));
  }
  auto argmin = [](const std::vector<double>& v) {
    return static_cast<int>(std::min_element(v.begin(), v.end()) - v.begin());
  };
  auto argmax = [](const std::vector<double>& v) {
    return static_cast<int>(std::max_element(v.begin(), v.end()) - v.begin());
  };
  EXPECT_EQ(argmin(criterion), 2);
  EXPECT_EQ(argmax(criterion), 1);
  EXPECT_EQ(argmin(determinant), 3);
  // A's observations hardly move the pose's determinant; B's shrink it.
  const double before = problem.state.pose_covariance().determinant();
  EXPECT_GT(determinant[2], 0.9 * before);
  EXPECT_LT(determinant[3], 0.5 * before);
}

TEST(SelectionPolicyTest, EachPolicyPicksItsKnownCandidate) {
  EXPECT_EQ(ChosenAlone(SelectionPolicy::kCriterion), 2);
  EXPECT_EQ(ChosenAlone(SelectionPolicy::kFirst), 0);
  EXPECT_EQ(ChosenAlone(SelectionPolicy::kLeastInformative), 1);
  EXPECT_EQ(ChosenAlone(SelectionPolicy::kDeterminant), 3);
  // With MAX = 2: first takes the first two in extraction order.
  KnownProblem problem = MakeKnownProblem();
  EXPECT_EQ(CorrectSelective(&problem.state, problem.matched, 2, SelectionPolicy::kFirst),
            (std::vector<int>{0, 1}));
}

TEST(SelectionPolicyTest, DeterminantIsTheBruteForceDeterminantAfterTheUpdate) {
  // PoseDeterminantAfter against applying the update and measuring det P_pp.
  Rng rng(35);
  for (int trial = 0; trial < 50; ++trial) {
    const SlamState state = MakeState(&rng, 6);
    for (const MatchedObservation& candidate : MakeMatched(&rng, state, 6)) {
      SlamState updated = state;
      updated.Update(candidate.feature, candidate.z, candidate.R);
      const double expected = updated.pose_covariance().determinant();
      EXPECT_NEAR(PoseDeterminantAfter(state, candidate), expected, 1e-9 * std::abs(expected))
          << "trial " << trial;
    }
  }
}

TEST(SelectionPolicyTest, RandomIsUniformWithoutRepeatsAndDeterministicBySeed) {
  // Same stream, same choice; the choice is the stream's first draw.
  Rng expected_rng(7);
  const int expected = static_cast<int>(expected_rng.Uniform() * 4);
  Rng a(7), b(7);
  EXPECT_EQ(ChosenAlone(SelectionPolicy::kRandom, &a), expected);
  EXPECT_EQ(ChosenAlone(SelectionPolicy::kRandom, &b), expected);
  // Every candidate about a quarter of the time over 2000 draws of one
  // stream (binomial std 1 %: bounds at 5 sigma).
  Rng rng(8);
  std::vector<int> counts(4, 0);
  for (int draw = 0; draw < 2000; ++draw) ++counts[ChosenAlone(SelectionPolicy::kRandom, &rng)];
  for (int i = 0; i < 4; ++i) {
    EXPECT_GT(counts[i], 400) << "candidate " << i;
    EXPECT_LT(counts[i], 600) << "candidate " << i;
  }
  // MAX = 4: a permutation, each candidate once.
  KnownProblem problem = MakeKnownProblem();
  std::vector<int> used =
      CorrectSelective(&problem.state, problem.matched, 4, SelectionPolicy::kRandom, &rng);
  std::sort(used.begin(), used.end());
  EXPECT_EQ(used, (std::vector<int>{0, 1, 2, 3}));
}

}  // namespace
}  // namespace mjslam::slam
