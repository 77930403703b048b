// SPDX-License-Identifier: BSD-3-Clause
#include "synth/object_slip.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "graspfill/core/random.hpp"
#include "graspfill/core/require.hpp"
#include "synth/angles.hpp"

namespace graspfill::synth {
namespace {

// Sub-stream of the scene seed, far from frame indices (renderer.cpp), the
// wobble's (scene.cpp) and the rig errors' (rig_errors.cpp).
constexpr uint64_t kSlipStream = 0xfffffffff000ULL;

}  // namespace

void SlipConfig::Validate() const {
  Require("SlipConfig", std::isfinite(distance_m) && distance_m >= 0.0 && distance_m < 0.05,
          "distance_m must be in [0, 0.05)");
  Require("SlipConfig", std::isfinite(max_tilt_deg) && max_tilt_deg >= 0.0 && max_tilt_deg <= 90.0,
          "max_tilt_deg must be in [0, 90]");
  Require("SlipConfig",
          start_min_fraction >= 0.0 && start_min_fraction <= start_max_fraction && start_max_fraction <= 1.0,
          "start fractions must satisfy 0 <= min <= max <= 1");
  Require("SlipConfig", std::isfinite(duration_s) && duration_s > 0.0 && duration_s <= 10.0,
          "duration_s must be in (0, 10]");
}

ObjectSlip::ObjectSlip(const SlipConfig& config, uint64_t seed, int64_t first_utime, int64_t last_utime)
    : config_(config) {
  config_.Validate();
  start_utime_ = first_utime;
  duration_us_ = std::llround(config_.duration_s * 1e6);
  if (!config_.any()) return;
  Rng rng(DeriveSeed(seed, kSlipStream));
  // Uniform on the cap within max_tilt of +z: cos(tilt) uniform in
  // [cos(max), 1] (Archimedes), azimuth uniform.
  const double cos_max = std::cos(config_.max_tilt_deg * kDegToRad);
  const double cos_tilt = 1.0 - rng.Uniform() * (1.0 - cos_max);
  const double sin_tilt = std::sqrt(std::max(0.0, 1.0 - cos_tilt * cos_tilt));
  const double azimuth = 2.0 * M_PI * rng.Uniform();
  direction_G_ =
      Eigen::Vector3d(sin_tilt * std::cos(azimuth), sin_tilt * std::sin(azimuth), cos_tilt).normalized();
  const double fraction =
      config_.start_min_fraction + rng.Uniform() * (config_.start_max_fraction - config_.start_min_fraction);
  start_utime_ = first_utime + std::llround(fraction * static_cast<double>(last_utime - first_utime));
}

int64_t ObjectSlip::end_utime() const { return start_utime_ + duration_us_; }

double ObjectSlip::Progress(int64_t utime) const {
  if (!config_.any() || utime <= start_utime_) return 0.0;
  if (utime >= end_utime()) return 1.0;
  const double x = static_cast<double>(utime - start_utime_) / static_cast<double>(duration_us_);
  return x * x * (3.0 - 2.0 * x);
}

Eigen::Isometry3d ObjectSlip::S_G(int64_t utime) const {
  Eigen::Isometry3d S = Eigen::Isometry3d::Identity();
  S.translation() = Progress(utime) * Displacement_G();
  return S;
}

Eigen::Isometry3d ObjectSlip::S_G_final() const {
  Eigen::Isometry3d S = Eigen::Isometry3d::Identity();
  S.translation() = Displacement_G();
  return S;
}

}  // namespace graspfill::synth
