#include "eval/map_divergence.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/angles.h"
#include "common/box_grid.h"  // Box2
#include "common/check.h"
#include "common/interrupt.h"

namespace mjslam::eval {

std::vector<ParamProblem> DivergenceParams::Validate() const {
  ParamChecker check;
  check.Positive("line_spacing_m", line_spacing_m);
  check.NonNegative("floor_std_m", floor_std_m);
  check.Positive("truth_std_m", truth_std_m);
  check.OneOf("weights", weights, {"feature", "gaussian"});
  check.NonNegative("margin_m", margin_m);
  return check.problems();
}

namespace {

// Adds `floor` to `covariance` and checks that the sum is positive definite.
Eigen::Matrix2d FlooredCovariance(const Eigen::Matrix2d& covariance, const Eigen::Matrix2d& floor,
                                  const MapFeature& feature) {
  const Eigen::Matrix2d C = 0.5 * (covariance + covariance.transpose()) + floor;
  if (!(C(0, 0) > 0.0 && C(0, 0) * C(1, 1) - C(0, 1) * C(1, 0) > 0.0)) {
    throw std::invalid_argument("divergence: feature " + std::to_string(feature.id) +
                                " has a covariance that is not positive definite with this "
                                "floor (use a positive floor_std_m)");
  }
  return C;
}

// Every Gaussian the same weight ("gaussian" weights).
void WeighEveryGaussianTheSame(GaussianMixture* mixture) {
  const double w = 1.0 / static_cast<double>(mixture->weights.size());
  for (double& weight : mixture->weights) weight = w;
}

}  // namespace

GaussianMixture MapToMixture(const Map& map, const DivergenceParams& params, MapRole role) {
  params.ValidateOrThrow();
  const double floor_std = role == MapRole::kTruth ? params.truth_std_m : params.floor_std_m;
  const Eigen::Matrix2d floor = floor_std * floor_std * Eigen::Matrix2d::Identity();
  // Features that become Gaussians, each with mass 1 / count.
  int count = 0;
  for (const MapFeature& f : map) {
    if (f.type == MapFeature::Type::kCorner || f.has_segment) ++count;
  }
  GaussianMixture mixture;
  for (const MapFeature& f : map) {
    if (f.type == MapFeature::Type::kCorner) {
      mixture.means.push_back(f.params);
      mixture.covariances.push_back(FlooredCovariance(f.covariance, floor, f));
      mixture.weights.push_back(1.0 / count);
      continue;
    }
    if (!f.has_segment) continue;
    const double r = f.params.x();
    const double al = f.params.y();
    const Eigen::Vector2d n(std::cos(al), std::sin(al));
    const Eigen::Vector2d t(-std::sin(al), std::cos(al));
    const double s_a = t.dot(f.p_WA);
    const double s_b = t.dot(f.p_WB);
    const int num = std::max(2, static_cast<int>(std::ceil(std::abs(s_b - s_a) /
                                                           params.line_spacing_m)) + 1);
    for (int k = 0; k < num; ++k) {
      const double s = s_a + (s_b - s_a) * k / (num - 1);
      Eigen::Matrix2d J;
      J.col(0) = n;
      J.col(1) = r * t - s * n;
      const Eigen::Matrix2d C = J * f.covariance * J.transpose();
      mixture.means.push_back(r * n + s * t);
      mixture.covariances.push_back(FlooredCovariance(C, floor, f));
      mixture.weights.push_back(1.0 / (static_cast<double>(count) * num));
    }
  }
  if (params.weights == "gaussian" && !mixture.weights.empty()) WeighEveryGaussianTheSame(&mixture);
  return mixture;
}

Box CommonBoundingBox(const std::vector<const GaussianMixture*>& mixtures, double margin_m) {
  Box box;
  box.min.setConstant(std::numeric_limits<double>::infinity());
  box.max.setConstant(-std::numeric_limits<double>::infinity());
  for (const GaussianMixture* m : mixtures) {
    for (const Eigen::Vector2d& p : m->means) {
      box.min = box.min.cwiseMin(p);
      box.max = box.max.cwiseMax(p);
    }
  }
  MJSLAM_CHECK(box.min.allFinite() && box.max.allFinite());
  box.min.array() -= margin_m;
  box.max.array() += margin_m;
  return box;
}

std::vector<Eigen::Vector2d> UniformPoints(const Box& box, int num_points, Rng* rng) {
  std::vector<Eigen::Vector2d> points(static_cast<std::size_t>(std::max(num_points, 0)));
  for (Eigen::Vector2d& p : points) {
    const double u = rng->Uniform();
    const double v = rng->Uniform();
    p = {box.min.x() + u * (box.max.x() - box.min.x()),
         box.min.y() + v * (box.max.y() - box.min.y())};
  }
  return points;
}

namespace {

// A k-d tree over the means of some Gaussians of a mixture: each node has
// the box around its Gaussians' means and their largest log-scale and
// largest covariance eigenvalue, so that every term of its Gaussians at a
// point is at most max_log_scale - d^2 / (2 max_eigenvalue), d the point's
// distance to the box.
class GaussianTree {
 public:
  struct Node {
    Box2 box;
    double max_log_scale = -std::numeric_limits<double>::infinity();
    double max_eigenvalue = 0.0;
    int begin = 0;  // members_[begin .. end)
    int end = 0;
    int first_child = -1;  // children first_child, first_child + 1; -1: a leaf
  };

  // A tree over `members` (indices into `means`, `log_scale`, `eigenvalue`).
  GaussianTree(std::vector<int> members, const std::vector<Eigen::Vector2d>& means,
               const std::vector<double>& log_scale, const std::vector<double>& eigenvalue)
      : members_(std::move(members)) {
    nodes_.push_back({});
    Build(0, 0, static_cast<int>(members_.size()), means, log_scale, eigenvalue);
  }

  const std::vector<Node>& nodes() const { return nodes_; }
  const std::vector<int>& members() const { return members_; }

 private:
  static constexpr int kLeafSize = 8;

  void Build(int node, int begin, int end, const std::vector<Eigen::Vector2d>& means,
             const std::vector<double>& log_scale, const std::vector<double>& eigenvalue) {
    Node n;
    n.begin = begin;
    n.end = end;
    n.box = {means[members_[begin]], means[members_[begin]]};
    for (int m = begin; m < end; ++m) {
      const int k = members_[m];
      n.box.lo = n.box.lo.cwiseMin(means[k]);
      n.box.hi = n.box.hi.cwiseMax(means[k]);
      n.max_log_scale = std::max(n.max_log_scale, log_scale[k]);
      n.max_eigenvalue = std::max(n.max_eigenvalue, eigenvalue[k]);
    }
    if (end - begin > kLeafSize) {
      // Split at the median along the box's longer side.
      const int axis = (n.box.hi - n.box.lo).x() >= (n.box.hi - n.box.lo).y() ? 0 : 1;
      const int middle = begin + (end - begin) / 2;
      std::nth_element(members_.begin() + begin, members_.begin() + middle,
                       members_.begin() + end, [&means, axis](int a, int b) {
                         return means[a](axis) < means[b](axis) ||
                                (means[a](axis) == means[b](axis) && a < b);
                       });
      n.first_child = static_cast<int>(nodes_.size());
      nodes_.push_back({});
      nodes_.push_back({});
      Build(n.first_child, begin, middle, means, log_scale, eigenvalue);
      Build(n.first_child + 1, middle, end, means, log_scale, eigenvalue);
    }
    nodes_[node] = n;
  }

  std::vector<int> members_;
  std::vector<Node> nodes_;
};

// The bound of a node's terms at p (+1 for rounding): every Gaussian of the
// node has its term at p below it.
double TermBound(const GaussianTree::Node& node, const Eigen::Vector2d& p) {
  const double dx = std::max({node.box.lo.x() - p.x(), 0.0, p.x() - node.box.hi.x()});
  const double dy = std::max({node.box.lo.y() - p.y(), 0.0, p.y() - node.box.hi.y()});
  return node.max_log_scale - 0.5 * (dx * dx + dy * dy) / node.max_eigenvalue + 1.0;
}

}  // namespace

std::vector<double> LogPmf(const GaussianMixture& mixture, const std::vector<Eigen::Vector2d>& points,
                           std::int64_t* terms_evaluated) {
  MJSLAM_CHECK(!mixture.means.empty());
  // Per Gaussian: log(weight / (2 pi sqrt(det C))), the inverse of C and
  // its largest eigenvalue.
  const std::size_t num = mixture.means.size();
  std::vector<double> log_scale(num);
  std::vector<Eigen::Vector3d> inverse(num);  // (a, b, c) of [[a, b], [b, c]]
  std::vector<double> eigenvalue(num);
  for (std::size_t k = 0; k < num; ++k) {
    const Eigen::Matrix2d& C = mixture.covariances[k];
    const double det = C(0, 0) * C(1, 1) - C(0, 1) * C(1, 0);
    MJSLAM_CHECK(det > 0.0 && mixture.means[k].allFinite());
    inverse[k] = {C(1, 1) / det, -C(0, 1) / det, C(0, 0) / det};
    log_scale[k] = std::log(mixture.weights[k]) - std::log(2.0 * kPi) - 0.5 * std::log(det);
    const double mid = 0.5 * (C(0, 0) + C(1, 1));
    const double half_gap = std::hypot(0.5 * (C(0, 0) - C(1, 1)), C(0, 1));
    eigenvalue[k] = mid + half_gap;
  }
  // A term is at most log_scale - d^2 / (2 eigenvalue) at a distance d from
  // its mean, so a point needs only the Gaussians near it: one k-d tree per
  // octave of the largest eigenvalue (so that a node's bound is not set by
  // much wider Gaussians) is searched best bound first, and a node is left
  // out once its bound lies more than 40 (+1 for rounding) below the
  // largest term found. That largest term only grows, so every term left
  // out is more than 40 below the largest of all; the terms kept are summed
  // in the order of the mixture: the same sum as over all Gaussians, bit for
  // bit.
  std::map<int, std::vector<int>> by_octave;
  for (std::size_t k = 0; k < num; ++k) {
    by_octave[std::ilogb(eigenvalue[k])].push_back(static_cast<int>(k));
  }
  std::vector<GaussianTree> trees;
  for (auto& [exponent, members] : by_octave) {
    trees.emplace_back(std::move(members), mixture.means, log_scale, eigenvalue);
  }
  std::int64_t evaluated = 0;
  std::vector<double> log_density(points.size());
  std::vector<std::pair<int, double>> kept;  // (Gaussian, term)
  struct Pending {
    double bound;
    int tree;
    int node;
    bool operator<(const Pending& other) const { return bound < other.bound; }
  };
  std::vector<Pending> queue;  // a max-heap by bound
  for (std::size_t i = 0; i < points.size(); ++i) {
    // A stop request is noticed every 1024 points (well under a second).
    if (i % 1024 == 0) ThrowIfInterrupted("map divergence");
    const Eigen::Vector2d& p = points[i];
    double largest = -std::numeric_limits<double>::infinity();
    kept.clear();
    queue.clear();
    for (std::size_t t = 0; t < trees.size(); ++t) {
      queue.push_back({TermBound(trees[t].nodes()[0], p), static_cast<int>(t), 0});
      std::push_heap(queue.begin(), queue.end());
    }
    while (!queue.empty()) {
      std::pop_heap(queue.begin(), queue.end());
      const Pending next = queue.back();
      queue.pop_back();
      // Every node still queued has a bound at most this one's.
      if (next.bound <= largest - 40.0) break;
      const GaussianTree& tree = trees[next.tree];
      const GaussianTree::Node& node = tree.nodes()[next.node];
      if (node.first_child >= 0) {
        for (int c = node.first_child; c <= node.first_child + 1; ++c) {
          const double bound = TermBound(tree.nodes()[c], p);
          if (bound <= largest - 40.0) continue;
          queue.push_back({bound, next.tree, c});
          std::push_heap(queue.begin(), queue.end());
        }
        continue;
      }
      for (int m = node.begin; m < node.end; ++m) {
        const int k = tree.members()[m];
        const double dx = p.x() - mixture.means[k].x();
        const double dy = p.y() - mixture.means[k].y();
        const Eigen::Vector3d& w = inverse[k];
        const double term =
            log_scale[k] - 0.5 * (w(0) * dx * dx + 2.0 * w(1) * dx * dy + w(2) * dy * dy);
        largest = std::max(largest, term);
        // A term already 40 below the largest found stays below the cutoff.
        if (term > largest - 40.0) kept.emplace_back(k, term);
      }
      evaluated += node.end - node.begin;
    }
    // Terms more than 40 below the largest add less than 1e-17 of it.
    std::sort(kept.begin(), kept.end());
    double sum = 0.0;
    const double cutoff = largest - 40.0;
    for (const auto& [k, term] : kept) {
      if (term > cutoff) sum += std::exp(term - largest);
    }
    log_density[i] = largest + std::log(sum);
  }
  if (terms_evaluated != nullptr) *terms_evaluated = evaluated;
  // Normalise over the points, also in log space.
  double largest = -std::numeric_limits<double>::infinity();
  for (const double l : log_density) largest = std::max(largest, l);
  double sum = 0.0;
  for (const double l : log_density) sum += std::exp(l - largest);
  const double log_total = largest + std::log(sum);
  for (double& l : log_density) l -= log_total;
  return log_density;
}

double KlDivergence(const std::vector<double>& log_p, const std::vector<double>& log_q) {
  MJSLAM_CHECK(log_p.size() == log_q.size());
  double d = 0.0;
  for (std::size_t i = 0; i < log_p.size(); ++i) d += std::exp(log_p[i]) * (log_p[i] - log_q[i]);
  return d;
}

std::vector<std::string> DivergenceLabels(const DivergencePair& pair) {
  return {pair.first + "_" + pair.second, pair.second + "_" + pair.first, pair.first + "_truth",
          pair.second + "_truth"};
}

bool HasDivergenceMass(const Map& map) {
  return std::any_of(map.begin(), map.end(), [](const MapFeature& f) {
    return f.type == MapFeature::Type::kCorner || f.has_segment;
  });
}

MapDivergences ComputeMapDivergences(const GaussianMixture& first, const GaussianMixture& second,
                                     const GaussianMixture& truth, int num_points, Rng* rng,
                                     const DivergenceParams& params) {
  params.ValidateOrThrow();
  const Box box = CommonBoundingBox({&first, &second, &truth}, params.margin_m);
  const std::vector<Eigen::Vector2d> points = UniformPoints(box, num_points, rng);
  const std::vector<double> a = LogPmf(first, points);
  const std::vector<double> b = LogPmf(second, points);
  const std::vector<double> t = LogPmf(truth, points);
  return {KlDivergence(a, b), KlDivergence(b, a), KlDivergence(a, t), KlDivergence(b, t)};
}

std::vector<DivergenceStatistics> DivergenceStudy(const Map& first, const Map& second,
                                                  const Map& truth, const DivergencePair& pair,
                                                  const std::vector<int>& num_points,
                                                  int realisations, const Rng& rng,
                                                  const DivergenceParams& params) {
  if (realisations < 1) {
    throw std::invalid_argument("divergence: realisations must be >= 1 (got " +
                                std::to_string(realisations) + ")");
  }
  const GaussianMixture a = MapToMixture(first, params);
  const GaussianMixture b = MapToMixture(second, params);
  const GaussianMixture t = MapToMixture(truth, params, MapRole::kTruth);
  const std::pair<const GaussianMixture*, std::string> mixtures[3] = {
      {&a, pair.first}, {&b, pair.second}, {&t, "truth"}};
  for (const auto& [m, name] : mixtures) {
    if (m->means.empty()) {
      throw std::invalid_argument("divergence: the " + name +
                                  " map has no corner and no line with a segment");
    }
  }
  const std::vector<std::string> labels = DivergenceLabels(pair);
  std::vector<DivergenceStatistics> rows;
  for (const int e : num_points) {
    if (e < 1) {
      throw std::invalid_argument("divergence: number of points must be >= 1 (got " +
                                  std::to_string(e) + ")");
    }
    std::vector<MapDivergences> samples;
    for (int k = 0; k < realisations; ++k) {
      ThrowIfInterrupted("map divergence");
      Rng stream = rng.Fork("divergence/" + std::to_string(e) + "/" + std::to_string(k));
      samples.push_back(ComputeMapDivergences(a, b, t, e, &stream, params));
    }
    for (int p = 0; p < 4; ++p) {
      auto value = [p](const MapDivergences& d) {
        const double v[4] = {d.first_second, d.second_first, d.first_truth, d.second_truth};
        return v[p];
      };
      double mean = 0.0;
      for (const MapDivergences& d : samples) mean += value(d);
      mean /= realisations;
      double variance = 0.0;
      for (const MapDivergences& d : samples) variance += std::pow(value(d) - mean, 2);
      variance = realisations > 1 ? variance / (realisations - 1) : 0.0;
      rows.push_back({e, labels[p], mean, variance});
    }
  }
  return rows;
}

}  // namespace mjslam::eval
