#include "common/rng.h"

namespace mjslam {
namespace {

// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective mixer that turns
// related seeds into unrelated ones.
std::uint64_t SplitMix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// FNV-1a hash of a name, stable across platforms and runs.
std::uint64_t HashName(std::string_view name) {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (const char c : name) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

}  // namespace

Rng::Rng(std::uint64_t seed) : seed_(seed), engine_(SplitMix64(seed)) {}

Rng Rng::Fork(std::string_view name) const {
  return Rng(SplitMix64(seed_ ^ HashName(name)));
}

double Rng::Uniform() { return uniform_(engine_); }

double Rng::Gaussian(double mean, double std) {
  return mean + std * normal_(engine_);
}

bool Rng::Bernoulli(double p) { return Uniform() < p; }

}  // namespace mjslam
