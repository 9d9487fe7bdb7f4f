// Benchmark of the map divergence's cost (eval/README.md, "Map divergence"):
// LogPmf of a building-like mixture, thin Gaussians (2 cm) every 5 cm along
// the walls of an n x n grid of 5 m rooms plus one line seen far off whose
// Gaussians widen to 1.4 m, at E = 2,000 or 20,000 points uniform in the
// grid's box (as `mjslam evaluate` draws them). Per (n, E): the Gaussians,
// the terms evaluated a point and the points a second (the trees'
// construction included, once per call); the difference between the two E
// gives the cost a point, which should grow about as log(Gaussians), and the
// construction, about Gaussians x log(Gaussians).
//
//   build/bench/mjslam_eval_bench --benchmark_min_time=0.2

#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <benchmark/benchmark.h>

#include "eval/map_divergence.h"

namespace mjslam::eval {
namespace {

GaussianMixture Building(int rooms) {
  GaussianMixture mixture;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double side = 5.0 * rooms;
  const int per_wall = static_cast<int>(side / 0.05);
  for (int wall = 0; wall <= rooms; ++wall) {
    for (int k = 0; k <= per_wall; ++k) {
      const double a = 0.0004 * (1.0 + 0.5 * unit(rng));
      mixture.means.emplace_back(5.0 * wall, 0.05 * k);
      mixture.covariances.push_back(Eigen::Vector2d(a, 0.0004).asDiagonal());
      mixture.means.emplace_back(0.05 * k, 5.0 * wall);
      mixture.covariances.push_back(Eigen::Vector2d(0.0004, a).asDiagonal());
    }
  }
  for (int k = 0; k < 200; ++k) {
    mixture.means.emplace_back(side + 10.0, 0.2 * k);
    mixture.covariances.push_back(Eigen::Vector2d(0.01 + 2.0 * k / 199.0, 0.0004).asDiagonal());
  }
  mixture.weights.assign(mixture.means.size(), 1.0 / mixture.means.size());
  return mixture;
}

void BM_LogPmf(benchmark::State& state) {
  const int rooms = static_cast<int>(state.range(0));
  const GaussianMixture mixture = Building(rooms);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> coordinate(-0.5, 5.0 * rooms + 10.5);
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < state.range(1); ++i) points.emplace_back(coordinate(rng), coordinate(rng));
  std::int64_t evaluated = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(LogPmf(mixture, points, &evaluated));
  }
  state.counters["gaussians"] = static_cast<double>(mixture.means.size());
  state.counters["terms_per_point"] = static_cast<double>(evaluated) / points.size();
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(points.size()));
}
BENCHMARK(BM_LogPmf)
    ->ArgsProduct({{5, 10, 20, 40}, {2000, 20000}})
    ->ArgNames({"rooms", "points"})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace mjslam::eval

BENCHMARK_MAIN();
