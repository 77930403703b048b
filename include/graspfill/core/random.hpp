// SPDX-License-Identifier: BSD-3-Clause
// Seeded random numbers (the synthetic data, a mesh's surface samples). The
// distributions are written out here (not std::normal_distribution) so that
// a seed gives the same numbers with every standard library, which keeps
// recordings and measurements reproducible across machines.
#pragma once

#include <cstdint>
#include <random>

namespace graspfill {

/// SplitMix64 finalizer: a cheap, well-mixed 64-bit hash.
uint64_t SplitMix64(uint64_t x);

/// Seed for one sub-stream (e.g. frame `index` of a scene seeded `seed`):
/// different indices give independent-looking streams, the same pair always
/// gives the same seed.
uint64_t DeriveSeed(uint64_t seed, uint64_t index);

/// std::mt19937_64 with portable uniform and normal draws. NOT thread safe.
class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}

  /// Uniform in [0, 1), 53 random bits.
  double Uniform();
  /// Standard normal (Box-Muller; every second call returns the pair's
  /// cached other half).
  double Normal();

 private:
  std::mt19937_64 engine_;
  double spare_normal_{0.0};
  bool has_spare_{false};
};

}  // namespace graspfill
