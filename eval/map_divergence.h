#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/params.h"
#include "common/rng.h"
#include "eval/map_types.h"

namespace mjslam::eval {

/// How a map becomes a probability mass function (docs/method.md, "Map divergence").
struct DivergenceParams {
  /// Lines become Gaussians spaced at most this far apart along their
  /// segment (at least two per line), metres.
  double line_spacing_m = 0.05;
  /// Standard deviation added in quadrature to every Gaussian of an
  /// estimated map (a filter's), metres, >= 0: its features never get
  /// thinner than this. 0 keeps each feature's own covariance, as the paper
  /// does (then a feature with a singular covariance is an error).
  double floor_std_m = 0.02;
  /// Standard deviation of the ground truth's Gaussians, metres, > 0: its
  /// features are exact (zero covariance) and become near-degenerate
  /// Gaussians of this size.
  double truth_std_m = 0.02;
  /// How the mass is split over a map: "feature" (each feature 1 / number of
  /// features, a line's share split evenly over its Gaussians) or "gaussian"
  /// (every Gaussian the same, so a line weighs by its seen length).
  std::string weights = "feature";
  /// The bounding box of the Gaussians' means is grown by this on every side
  /// before the points are drawn in it, metres.
  double margin_m = 0.5;

  std::vector<ParamProblem> Validate() const;
  void ValidateOrThrow() const { ThrowIfProblems(Validate(), "divergence"); }
};

/// A map as a weighted sum of 2-D Gaussians in W (Eq. 23 of the paper).
struct GaussianMixture {
  std::vector<Eigen::Vector2d> means;
  std::vector<Eigen::Matrix2d> covariances;
  /// Sum to 1 (each feature 1 / number of features, a line's split evenly
  /// over its Gaussians).
  std::vector<double> weights;
};

/// Which floor a map's Gaussians get: `floor_std_m` (an estimated map) or
/// `truth_std_m` (the ground truth).
enum class MapRole { kEstimate, kTruth };

/// The mixture of a map. A corner is one Gaussian at its point with its
/// covariance (+ floor). A line with a segment becomes Gaussians at evenly
/// spaced positions s along it, p(s) = r n + s t (n = (cos al, sin al),
/// t = (-sin al, cos al)), each with covariance J C J^T + floor, J = dp /
/// d(r, al) = [n, r t - s n] at fixed s; lines without a segment are left
/// out. The floor is `floor_std_m^2 I` for `MapRole::kEstimate`,
/// `truth_std_m^2 I` for `MapRole::kTruth`. Throws ParamError for invalid
/// params, std::invalid_argument for a Gaussian whose covariance is not
/// positive definite (naming the feature's id).
GaussianMixture MapToMixture(const Map& map, const DivergenceParams& params = {},
                             MapRole role = MapRole::kEstimate);

/// An axis-aligned box in W, metres.
struct Box {
  Eigen::Vector2d min = Eigen::Vector2d::Zero();
  Eigen::Vector2d max = Eigen::Vector2d::Zero();
};

/// The box around every mixture's means, grown by `margin_m`. At least one
/// mixture must have a Gaussian (checked).
Box CommonBoundingBox(const std::vector<const GaussianMixture*>& mixtures, double margin_m);

/// `num_points` points drawn uniformly in `box` from `rng`.
std::vector<Eigen::Vector2d> UniformPoints(const Box& box, int num_points, Rng* rng);

/// The log of the mixture's probability mass function over `points` (Eqs.
/// 19-22): log density at each point, normalised so that the masses sum to
/// 1, computed in log space (log-sum-exp), so far points keep a finite log.
/// Terms more than 40 below a point's largest are left out (they add less
/// than 1e-17); the result is bit for bit the sum over every Gaussian, at
/// the cost of the Gaussians near each point. When `terms_evaluated` is
/// given, it receives how many Gaussian terms were evaluated in all (the
/// cost's measure, for tests and benchmarks).
std::vector<double> LogPmf(const GaussianMixture& mixture,
                           const std::vector<Eigen::Vector2d>& points,
                           std::int64_t* terms_evaluated = nullptr);

/// Kullback-Leibler divergence D(p || q) = sum_i p_i log(p_i / q_i) (Eq. 18)
/// of two pmfs given by their logs over the same points (sizes checked).
double KlDivergence(const std::vector<double>& log_p, const std::vector<double>& log_q);

/// The two maps a divergence study compares, by name (a run's filter names:
/// "classical" and "selective" by default), which label its rows.
struct DivergencePair {
  std::string first = "classical";
  std::string second = "selective";
};

/// The four labels of `pair`'s divergences, in the order of MapDivergences:
/// "<first>_<second>", "<second>_<first>", "<first>_truth", "<second>_truth".
std::vector<std::string> DivergenceLabels(const DivergencePair& pair);

/// Whether MapToMixture gives `map` a Gaussian (a corner, or a line with a
/// seen segment): whether it has something for the divergence to compare.
bool HasDivergenceMass(const Map& map);

/// The four divergences of one realisation, nats: between two maps (first
/// and second, e.g. two filters') in both orders and from each to the ground
/// truth.
struct MapDivergences {
  double first_second = 0.0;  // D(first || second)
  double second_first = 0.0;  // D(second || first)
  double first_truth = 0.0;   // D(first || truth)
  double second_truth = 0.0;  // D(second || truth)
};

/// One realisation: `num_points` points uniform in the common bounding box of
/// the three maps (grown by margin_m), drawn from `rng`.
MapDivergences ComputeMapDivergences(const GaussianMixture& first, const GaussianMixture& second,
                                     const GaussianMixture& truth, int num_points, Rng* rng,
                                     const DivergenceParams& params = {});

/// Mean and variance (unbiased, over the realisations) of one pair's
/// divergence at one number of points: a row of divergence.csv.
struct DivergenceStatistics {
  int num_points = 0;
  /// One of DivergenceLabels(pair): "classical_selective", ... by default.
  std::string pair;
  double mean = 0.0;
  double variance = 0.0;
};

/// The paper's Figs. 6 and 7 for the maps `first` and `second` (named by
/// `pair`): for each entry of `num_points`, `realisations` independent
/// realisations (realisation k at E points draws from
/// rng.Fork("divergence/E/k"), whatever the pair, so every number is
/// reproducible on its own). Rows in the order of `num_points`, then of
/// DivergenceLabels(pair). realisations >= 1 and every num_points >= 1, and
/// each map has a corner or a line with a segment (else throws
/// std::invalid_argument naming the map: pair.first, pair.second or truth).
/// Throws Interrupted (common/interrupt.h) within a fraction of a second of a
/// stop request.
std::vector<DivergenceStatistics> DivergenceStudy(const Map& first, const Map& second,
                                                  const Map& truth, const DivergencePair& pair,
                                                  const std::vector<int>& num_points,
                                                  int realisations, const Rng& rng,
                                                  const DivergenceParams& params = {});

}  // namespace mjslam::eval
