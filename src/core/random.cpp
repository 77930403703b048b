// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/core/random.hpp"

#include <cmath>

namespace graspfill {

uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

uint64_t DeriveSeed(uint64_t seed, uint64_t index) {
  // Hash twice so that neighbouring (seed, index) pairs do not collide.
  return SplitMix64(SplitMix64(seed) ^ SplitMix64(index + 0x5851f42d4c957f2dULL));
}

double Rng::Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

double Rng::Normal() {
  constexpr double kTwoPi = 6.283185307179586476925;
  if (has_spare_) {
    has_spare_ = false;
    return spare_normal_;
  }
  const double u1 = 1.0 - Uniform();  // in (0, 1]: a finite log
  const double u2 = Uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  spare_normal_ = r * std::sin(kTwoPi * u2);
  has_spare_ = true;
  return r * std::cos(kTwoPi * u2);
}

}  // namespace graspfill
