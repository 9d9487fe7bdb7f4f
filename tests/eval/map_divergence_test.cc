// The paper's map divergence: mixtures, pmfs and Kullback-Leibler divergence.
#include "eval/map_divergence.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "eval/ground_truth.h"

namespace mjslam::eval {
namespace {

// The inner walls of an 8 x 6 m room as a ground truth map.
Map Room() {
  auto box = [](double x0, double y0, double x1, double y1) {
    return WallRectangle{{Eigen::Vector2d(x0, y0), Eigen::Vector2d(x1, y0),
                          Eigen::Vector2d(x1, y1), Eigen::Vector2d(x0, y1)}};
  };
  return BuildGroundTruthMap({box(-4.15, -3.15, 4.15, -3.0), box(4.0, -3.15, 4.15, 3.15),
                              box(-4.15, 3.0, 4.15, 3.15), box(-4.15, -3.15, -4.0, 3.15)});
}

// `map` with every feature moved by `offset` and given covariance `var` I.
Map Shifted(const Map& map, const Eigen::Vector2d& offset, double var) {
  Map out = map;
  for (MapFeature& f : out) {
    f.covariance = var * Eigen::Matrix2d::Identity();
    if (f.type == MapFeature::Type::kCorner) {
      f.params += offset;
      continue;
    }
    const Eigen::Vector2d n(std::cos(f.params.y()), std::sin(f.params.y()));
    f.params.x() += n.dot(offset);
    f.p_WA += offset;
    f.p_WB += offset;
  }
  return out;
}

TEST(MapDivergenceTest, MixtureOfALinePropagatesItsCovariance) {
  MapFeature line;
  line.type = MapFeature::Type::kLine;
  line.params = {2.0, 0.0};  // x = 2
  line.covariance = Eigen::Vector2d(1e-4, 1e-6).asDiagonal();
  line.has_segment = true;
  line.p_WA = {2.0, -1.0};
  line.p_WB = {2.0, 1.0};
  DivergenceParams params;
  params.line_spacing_m = 0.5;
  const GaussianMixture m = MapToMixture({line}, params);
  ASSERT_EQ(m.means.size(), 5u);  // s = -1, -0.5, 0, 0.5, 1
  double total = 0.0;
  for (const double w : m.weights) total += w;
  EXPECT_NEAR(total, 1.0, 1e-12);
  // At s = 1 (the point (2, 1)): J = [n, r t - s n] = [[1, -1], [0, 2]].
  EXPECT_NEAR((m.means[4] - Eigen::Vector2d(2.0, 1.0)).norm(), 0.0, 1e-12);
  Eigen::Matrix2d J;
  J << 1.0, -1.0, 0.0, 2.0;
  const Eigen::Matrix2d expected = J * line.covariance * J.transpose() +
                                   params.floor_std_m * params.floor_std_m * Eigen::Matrix2d::Identity();
  EXPECT_NEAR((m.covariances[4] - expected).norm(), 0.0, 1e-15);
  // The propagated covariance against central differences of p(r, al) at s.
  const double s = 1.0;
  auto point = [s](double r, double al) {
    return Eigen::Vector2d(r * std::cos(al) - s * std::sin(al), r * std::sin(al) + s * std::cos(al));
  };
  const double h = 1e-6;
  Eigen::Matrix2d numeric;
  numeric.col(0) = (point(2.0 + h, 0.0) - point(2.0 - h, 0.0)) / (2 * h);
  numeric.col(1) = (point(2.0, h) - point(2.0, -h)) / (2 * h);
  EXPECT_NEAR((numeric - J).norm(), 0.0, 1e-8);
}

TEST(MapDivergenceTest, PmfSumsToOneAndDivergenceOfAMapWithItselfIsZero) {
  const GaussianMixture truth = MapToMixture(Room());
  Rng rng(11);
  const Box box = CommonBoundingBox({&truth}, 0.5);
  const std::vector<Eigen::Vector2d> points = UniformPoints(box, 2000, &rng);
  for (const Eigen::Vector2d& p : points) {
    ASSERT_TRUE(p.x() >= box.min.x() && p.x() <= box.max.x());
    ASSERT_TRUE(p.y() >= box.min.y() && p.y() <= box.max.y());
  }
  const std::vector<double> log_p = LogPmf(truth, points);
  double total = 0.0;
  for (const double l : log_p) {
    ASSERT_TRUE(std::isfinite(l));
    total += std::exp(l);
  }
  EXPECT_NEAR(total, 1.0, 1e-12);
  EXPECT_NEAR(KlDivergence(log_p, log_p), 0.0, 1e-15);
}

TEST(MapDivergenceTest, DivergenceGrowsWithTheMapErrorAndIsAsymmetric) {
  // Seed 5: a map 1 cm off the truth is closer than one 5 cm off, in every
  // realisation; D(a||b) != D(b||a) in general; all divergences >= 0.
  const Map truth = Room();
  const GaussianMixture t = MapToMixture(truth);
  const GaussianMixture near = MapToMixture(Shifted(truth, {0.01, 0.0}, 1e-4));
  const GaussianMixture far = MapToMixture(Shifted(truth, {0.05, -0.02}, 4e-4));
  const Rng root(5);
  for (int k = 0; k < 5; ++k) {
    Rng rng = root.Fork("r" + std::to_string(k));
    const MapDivergences d = ComputeMapDivergences(near, far, t, 2000, &rng);
    EXPECT_LT(d.first_truth, d.second_truth) << k;
    EXPECT_GE(d.first_truth, 0.0);
    EXPECT_GT(d.first_second, 0.0);
    EXPECT_GT(d.second_first, 0.0);
    EXPECT_NE(d.first_second, d.second_first);
  }
}

TEST(MapDivergenceTest, StudyIsReproducibleRowByRow) {
  const Map truth = Room();
  const Map a = Shifted(truth, {0.02, 0.0}, 1e-4);
  const Map b = Shifted(truth, {0.0, 0.03}, 2e-4);
  const Rng rng(3);
  const DivergencePair pair;  // classical, selective
  const std::vector<DivergenceStatistics> first =
      DivergenceStudy(a, b, truth, pair, {100, 1000}, 5, rng);
  const std::vector<DivergenceStatistics> second =
      DivergenceStudy(a, b, truth, pair, {100, 1000}, 5, rng);
  ASSERT_EQ(first.size(), 8u);
  for (std::size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(first[i].mean, second[i].mean);  // bit for bit
    EXPECT_EQ(first[i].variance, second[i].variance);
  }
  EXPECT_EQ(first[0].pair, "classical_selective");
  EXPECT_EQ(first[3].pair, "selective_truth");
  EXPECT_EQ(first[4].num_points, 1000);
  // Each #E has its own streams: a study of 1000 points alone gives the same.
  const std::vector<DivergenceStatistics> alone = DivergenceStudy(a, b, truth, pair, {1000}, 5, rng);
  for (int p = 0; p < 4; ++p) EXPECT_EQ(alone[p].mean, first[4 + p].mean);
  for (const DivergenceStatistics& row : first) {
    EXPECT_GT(row.mean, 0.0);
    EXPECT_GT(row.variance, 0.0);
  }
  EXPECT_THROW(DivergenceStudy(a, b, truth, pair, {0}, 2, rng), std::invalid_argument);
  EXPECT_THROW(DivergenceStudy(a, b, truth, pair, {10}, 0, rng), std::invalid_argument);
}

// Any two maps by name: the rows are labelled by the pair's names, and the
// numbers are those of the same maps under the default names (the streams do
// not depend on the names).
TEST(MapDivergenceTest, RowsAreLabelledByThePairsNames) {
  const Map truth = Room();
  const Map a = Shifted(truth, {0.02, 0.0}, 1e-4);
  const Map b = Shifted(truth, {0.0, 0.03}, 2e-4);
  const Rng rng(3);
  const DivergencePair named{"dead_reckoning", "ekf_b"};
  EXPECT_EQ(DivergenceLabels(named),
            (std::vector<std::string>{"dead_reckoning_ekf_b", "ekf_b_dead_reckoning",
                                      "dead_reckoning_truth", "ekf_b_truth"}));
  EXPECT_EQ(DivergenceLabels(DivergencePair{}),
            (std::vector<std::string>{"classical_selective", "selective_classical",
                                      "classical_truth", "selective_truth"}));
  const std::vector<DivergenceStatistics> rows = DivergenceStudy(a, b, truth, named, {100}, 3, rng);
  const std::vector<DivergenceStatistics> paper =
      DivergenceStudy(a, b, truth, DivergencePair{}, {100}, 3, rng);
  ASSERT_EQ(rows.size(), 4u);
  for (int p = 0; p < 4; ++p) {
    EXPECT_EQ(rows[p].pair, DivergenceLabels(named)[p]);
    EXPECT_EQ(rows[p].mean, paper[p].mean);
    EXPECT_EQ(rows[p].variance, paper[p].variance);
  }
  // A map with nothing to compare is an error naming it by its name.
  Map unseen = a;
  for (MapFeature& f : unseen) f.has_segment = false;
  unseen.erase(std::remove_if(unseen.begin(), unseen.end(),
                              [](const MapFeature& f) {
                                return f.type == MapFeature::Type::kCorner;
                              }),
               unseen.end());
  EXPECT_TRUE(HasDivergenceMass(a));
  EXPECT_FALSE(HasDivergenceMass(unseen));
  EXPECT_FALSE(HasDivergenceMass(Map{}));
  try {
    DivergenceStudy(a, unseen, truth, named, {100}, 3, rng);
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()),
              "divergence: the ekf_b map has no corner and no line with a segment");
  }
}

TEST(MapDivergenceTest, FloorsByRoleAndWeightsByOption) {
  MapFeature line;
  line.type = MapFeature::Type::kLine;
  line.params = {2.0, 0.0};  // x = 2, 2 m seen
  line.covariance = Eigen::Vector2d(1e-6, 1e-8).asDiagonal();
  line.has_segment = true;
  line.p_WA = {2.0, -1.0};
  line.p_WB = {2.0, 1.0};
  MapFeature corner;
  corner.type = MapFeature::Type::kCorner;
  corner.id = 7;
  corner.params = {0.0, 0.0};
  corner.covariance = 4e-6 * Eigen::Matrix2d::Identity();
  DivergenceParams params;
  params.line_spacing_m = 0.5;  // 5 Gaussians on the line
  params.floor_std_m = 0.0;
  params.truth_std_m = 0.001;
  // An estimate keeps its own covariance with floor 0; the truth gets truth_std_m.
  const GaussianMixture estimate = MapToMixture({corner, line}, params);
  ASSERT_EQ(estimate.means.size(), 6u);
  EXPECT_NEAR((estimate.covariances[0] - corner.covariance).norm(), 0.0, 1e-18);
  const GaussianMixture truth = MapToMixture({corner, line}, params, MapRole::kTruth);
  EXPECT_NEAR((truth.covariances[0] - corner.covariance - 1e-6 * Eigen::Matrix2d::Identity()).norm(),
              0.0, 1e-18);
  // "feature": the corner has half the mass; "gaussian": a sixth, like each of the line's five.
  EXPECT_DOUBLE_EQ(estimate.weights[0], 0.5);
  EXPECT_DOUBLE_EQ(estimate.weights[1], 0.1);
  params.weights = "gaussian";
  const GaussianMixture even = MapToMixture({corner, line}, params);
  for (const double w : even.weights) EXPECT_DOUBLE_EQ(w, 1.0 / 6.0);
  // Bad values: a clear error naming the key or the feature.
  params.weights = "length";
  EXPECT_THROW(MapToMixture({corner}, params), ParamError);
  params.weights = "feature";
  params.floor_std_m = -0.01;
  EXPECT_THROW(MapToMixture({corner}, params), ParamError);
  params.floor_std_m = 0.0;
  params.truth_std_m = 0.0;
  EXPECT_THROW(MapToMixture({corner}, params, MapRole::kTruth), ParamError);
  params.truth_std_m = 0.001;
  corner.covariance.setZero();
  try {
    MapToMixture({corner}, params);
    ADD_FAILURE() << "a singular covariance with floor 0 was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("feature 7"), std::string::npos) << error.what();
  }
}

TEST(MapDivergenceTest, BothFloorsRankAMapThreeMillimetresOffAboveOneOneMillimetreOff) {
  // Two maps 1 mm and 3 mm off the truth, each feature with a 1 mm standard
  // deviation (the size of the filters' map errors). With the 2 cm floor on
  // every Gaussian the divergence to the truth is small, about d^2 / (2
  // sigma^2), so the 3 mm map's is about 9 times the 1 mm map's; with each
  // feature's own covariance and a 1 mm truth (the paper's choice) it is
  // larger and still ranks the two. Seed 9, 3 realisations of 10000 points.
  const Map truth = Room();
  const Map near = Shifted(truth, {0.001, 0.0}, 1e-6);
  const Map far = Shifted(truth, {0.003, 0.0}, 1e-6);
  DivergenceParams floored;
  DivergenceParams own;
  own.floor_std_m = 0.0;
  own.truth_std_m = 0.001;
  const Rng rng(9);
  const std::vector<DivergenceStatistics> a =
      DivergenceStudy(near, far, truth, DivergencePair{}, {10000}, 3, rng, floored);
  const std::vector<DivergenceStatistics> b =
      DivergenceStudy(near, far, truth, DivergencePair{}, {10000}, 3, rng, own);
  // Rows: classical_selective, selective_classical, classical_truth (near), selective_truth (far).
  EXPECT_LT(a[2].mean, 0.01);
  EXPECT_GT(a[3].mean / a[2].mean, 7.0) << a[2].mean << " " << a[3].mean;
  EXPECT_LT(a[3].mean / a[2].mean, 11.0) << a[2].mean << " " << a[3].mean;
  EXPECT_GT(b[2].mean, 100.0 * a[2].mean) << b[2].mean;
  EXPECT_GT(b[3].mean, 1.2 * b[2].mean) << b[2].mean << " " << b[3].mean;
}

// The mixture's log PMF over every Gaussian (the direct sum, before the
// Gaussians near each point were looked up in a grid).
std::vector<double> DirectLogPmf(const GaussianMixture& mixture,
                                 const std::vector<Eigen::Vector2d>& points) {
  const std::size_t num = mixture.means.size();
  std::vector<double> log_scale(num);
  std::vector<Eigen::Vector3d> inverse(num);
  for (std::size_t k = 0; k < num; ++k) {
    const Eigen::Matrix2d& C = mixture.covariances[k];
    const double det = C(0, 0) * C(1, 1) - C(0, 1) * C(1, 0);
    inverse[k] = {C(1, 1) / det, -C(0, 1) / det, C(0, 0) / det};
    log_scale[k] = std::log(mixture.weights[k]) - std::log(2.0 * kPi) - 0.5 * std::log(det);
  }
  std::vector<double> log_density(points.size());
  std::vector<double> terms(num);
  for (std::size_t i = 0; i < points.size(); ++i) {
    double largest = -std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < num; ++k) {
      const double dx = points[i].x() - mixture.means[k].x();
      const double dy = points[i].y() - mixture.means[k].y();
      const Eigen::Vector3d& w = inverse[k];
      terms[k] = log_scale[k] - 0.5 * (w(0) * dx * dx + 2.0 * w(1) * dx * dy + w(2) * dy * dy);
      largest = std::max(largest, terms[k]);
    }
    double sum = 0.0;
    for (std::size_t k = 0; k < num; ++k) {
      if (terms[k] > largest - 40.0) sum += std::exp(terms[k] - largest);
    }
    log_density[i] = largest + std::log(sum);
  }
  double largest = -std::numeric_limits<double>::infinity();
  for (const double l : log_density) largest = std::max(largest, l);
  double sum = 0.0;
  for (const double l : log_density) sum += std::exp(l - largest);
  for (double& l : log_density) l -= largest + std::log(sum);
  return log_density;
}

TEST(MapDivergenceTest, LogPmfEqualsTheDirectSumOverEveryGaussian) {
  // Gaussians of very different sizes and weights, clustered and spread,
  // and points near them, between them and far outside (seed 11).
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> position(-20.0, 20.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  GaussianMixture mixture;
  for (int k = 0; k < 400; ++k) {
    const double scale = k % 50 == 0 ? 0.2 : 0.02;
    const Eigen::Vector2d mean = k % 3 == 0 ? Eigen::Vector2d(position(rng), position(rng))
                                            : Eigen::Vector2d(0.1 * position(rng), 1.0);
    Eigen::Matrix2d A;
    A << scale * (0.2 + unit(rng)), scale * unit(rng), 0.0, scale * (0.2 + unit(rng));
    mixture.means.push_back(mean);
    mixture.covariances.push_back(A * A.transpose());
    mixture.weights.push_back(0.5 + unit(rng));
  }
  double total = 0.0;
  for (const double w : mixture.weights) total += w;
  for (double& w : mixture.weights) w /= total;
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < 3000; ++i) {
    points.emplace_back(3.0 * position(rng), i % 2 == 0 ? 1.0 + 0.01 * position(rng)
                                                          : 3.0 * position(rng));
  }
  const std::vector<double> fast = LogPmf(mixture, points);
  const std::vector<double> direct = DirectLogPmf(mixture, points);
  ASSERT_EQ(fast.size(), direct.size());
  int differ = 0;
  for (std::size_t i = 0; i < fast.size(); ++i) differ += fast[i] != direct[i];
  EXPECT_EQ(differ, 0);
}

// A map like a lost filter's beside a building's: thin Gaussians (2 cm, the
// floor) every 5 cm along the walls of a 40 x 40 m grid of 5 m rooms, and a
// line seen far off with a growing angle error, whose Gaussians widen to
// about 1.4 m (eigenvalues 0.01 to 2 m^2), 10 m outside the grid; 2,000
// points uniform in a box with 10 m of empty space around (seed 5).
struct WideAndThin {
  GaussianMixture mixture;
  std::vector<Eigen::Vector2d> points;
};

WideAndThin WideAndThinMap() {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  WideAndThin out;
  GaussianMixture& mixture = out.mixture;
  auto add = [&mixture](const Eigen::Vector2d& mean, const Eigen::Matrix2d& covariance) {
    mixture.means.push_back(mean);
    mixture.covariances.push_back(covariance);
  };
  for (int wall = 0; wall <= 8; ++wall) {
    for (int k = 0; k <= 800; ++k) {
      // Slightly anisotropic, as a line's J C J^T + floor.
      const double a = 0.0004 * (1.0 + 0.5 * unit(rng));
      add({5.0 * wall, 0.05 * k}, Eigen::Vector2d(a, 0.0004).asDiagonal());
      add({0.05 * k, 5.0 * wall}, Eigen::Vector2d(0.0004, a).asDiagonal());
    }
  }
  for (int k = 0; k < 200; ++k) {
    const double wide = 0.01 + 2.0 * k / 199.0;
    add({50.0, -10.0 + 0.2 * k}, Eigen::Vector2d(wide, 0.0004).asDiagonal());
  }
  mixture.weights.assign(mixture.means.size(), 1.0 / mixture.means.size());
  std::uniform_real_distribution<double> x(-10.0, 60.0);
  std::uniform_real_distribution<double> y(-10.0, 50.0);
  for (int i = 0; i < 2000; ++i) out.points.emplace_back(x(rng), y(rng));
  return out;
}

TEST(MapDivergenceTest, LogPmfOfThinAndWideGaussiansEqualsTheDirectSum) {
  const WideAndThin map = WideAndThinMap();
  const std::vector<double> fast = LogPmf(map.mixture, map.points);
  const std::vector<double> direct = DirectLogPmf(map.mixture, map.points);
  ASSERT_EQ(fast.size(), direct.size());
  int differ = 0;
  for (std::size_t i = 0; i < fast.size(); ++i) differ += fast[i] != direct[i];
  EXPECT_EQ(differ, 0);
}

// The cost: a point evaluates the Gaussians whose term can be within 40 of
// its largest, not those of a square as wide as its distance to the nearest
// wall, nor every Gaussian once the widest one bounds the search.
TEST(MapDivergenceTest, LogPmfEvaluatesOnlyTheGaussiansNearEachPoint) {
  const WideAndThin map = WideAndThinMap();
  std::int64_t evaluated = 0;
  LogPmf(map.mixture, map.points, &evaluated);
  const double per_point = static_cast<double>(evaluated) / map.points.size();
  // 14,618 Gaussians; 118 a point measured.
  EXPECT_LT(per_point, 200.0) << "of " << map.mixture.means.size();
}

}  // namespace
}  // namespace mjslam::eval
