#pragma once

#include <cstdint>
#include <random>
#include <string_view>

namespace mjslam {

/// A seeded random stream. Every consumer forks its own named stream from the
/// run's root Rng, so adding a noise source never shifts the numbers of the
/// others. Same seed and name give the same numbers on the same binary.
class Rng {
 public:
  explicit Rng(std::uint64_t seed);

  /// An independent stream whose seed is derived from this stream's seed and
  /// `name` (not from how many numbers this stream has drawn).
  Rng Fork(std::string_view name) const;

  /// Uniform in [0, 1).
  double Uniform();
  /// Gaussian with the given mean and standard deviation (std >= 0).
  double Gaussian(double mean, double std);
  /// True with probability p.
  bool Bernoulli(double p);

  /// The seed this stream started from.
  std::uint64_t seed() const { return seed_; }
  /// The underlying engine, for std distributions.
  std::mt19937_64& engine() { return engine_; }

 private:
  std::uint64_t seed_;
  std::mt19937_64 engine_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
};

}  // namespace mjslam
