// SPDX-License-Identifier: BSD-3-Clause
#include "synth/sensor_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "graspfill/core/random.hpp"
#include "graspfill/core/require.hpp"
#include "synth/angles.hpp"

namespace graspfill::synth {
namespace {

bool IsProbability(double p) { return p >= 0.0 && p <= 1.0; }

}  // namespace

SensorModelConfig SensorModelConfig::Ideal() {
  SensorModelConfig config;
  config.noise = false;
  config.quantize = false;
  config.grazing_start_deg = 90.0;
  config.grazing_full_deg = 90.0;
  config.edge_dropout_prob = 0.0;
  config.random_dropout_prob = 0.0;
  return config;
}

void SensorModelConfig::Validate() const {
  Require("SensorModelConfig", sigma_base_m >= 0.0 && sigma_quadratic_m >= 0.0 && sigma_angular_m >= 0.0,
          "noise coefficients must be >= 0");
  Require("SensorModelConfig", baseline_m > 0.0 && disparity_steps_per_px > 0.0,
          "baseline_m and disparity_steps_per_px must be > 0");
  Require("SensorModelConfig", min_range_m >= 0.0 && min_range_m < max_range_m,
          "need 0 <= min_range_m < max_range_m");
  Require("SensorModelConfig",
          grazing_start_deg >= 0.0 && grazing_start_deg <= grazing_full_deg && grazing_full_deg <= 90.0,
          "need 0 <= grazing_start_deg <= grazing_full_deg <= 90");
  Require("SensorModelConfig", edge_jump_m > 0.0, "edge_jump_m must be > 0");
  Require("SensorModelConfig", IsProbability(mixed_pixel_prob), "mixed_pixel_prob must lie in [0, 1]");
  Require("SensorModelConfig", dark_patch_share >= 0.0 && dark_patch_share <= 0.5,
          "dark_patch_share must lie in [0, 0.5]");
  Require("SensorModelConfig", dark_patch_size_m >= 0.001 && dark_patch_size_m <= 0.1,
          "dark_patch_size_m must lie in [0.001, 0.1]");
  Require("SensorModelConfig", depth_scale > 0.5 && depth_scale < 2.0, "depth_scale must lie in (0.5, 2)");
  Require("SensorModelConfig", intrinsics_scale > 0.5 && intrinsics_scale < 2.0,
          "intrinsics_scale must lie in (0.5, 2)");
  Require("SensorModelConfig", std::isfinite(wobble_m) && std::abs(wobble_m) <= 0.05 && wobble_period_s > 0.0,
          "wobble_m must lie in [-0.05, 0.05] m and wobble_period_s be > 0");
  Require("SensorModelConfig", IsProbability(edge_dropout_prob) && IsProbability(random_dropout_prob),
          "dropout probabilities must be in [0, 1]");
}

double AxialNoiseSigma(const SensorModelConfig& config, double z_m, double incidence_rad) {
  const double dz = z_m - config.sigma_reference_depth_m;
  double sigma = config.sigma_base_m + config.sigma_quadratic_m * dz * dz;
  // The angular term diverges at 90 deg; those pixels are dropped anyway,
  // so cap the angle just below it.
  const double theta = std::clamp(incidence_rad, 0.0, 0.5 * M_PI - 1e-3);
  const double ratio = theta / (0.5 * M_PI - theta);
  sigma += config.sigma_angular_m / std::sqrt(std::max(z_m, 1e-3)) * ratio * ratio;
  return sigma;
}

double QuantizeDepth(const SensorModelConfig& config, double fx_px, double z_m) {
  if (!(z_m > 0.0)) return z_m;
  const double bf = config.baseline_m * fx_px;
  const double steps = std::round(bf / z_m * config.disparity_steps_per_px);
  if (steps <= 0.0) return 0.0;  // beyond the smallest disparity: no return
  return bf / (steps / config.disparity_steps_per_px);
}

namespace {

// The depth of the 4-neighbour of pixel i with a return that differs most
// from i's (i's own when none has a return).
double FarthestNeighbourDepth(const std::vector<float>& z, int width, int height, size_t i) {
  const int u = static_cast<int>(i % static_cast<size_t>(width));
  const int v = static_cast<int>(i / static_cast<size_t>(width));
  double best = z[i];
  auto consider = [&](size_t j) {
    if (z[j] > 0.0f && std::abs(z[j] - z[i]) > std::abs(best - z[i])) best = z[j];
  };
  if (u > 0) consider(i - 1);
  if (u + 1 < width) consider(i + 1);
  if (v > 0) consider(i - static_cast<size_t>(width));
  if (v + 1 < height) consider(i + static_cast<size_t>(width));
  return best;
}

}  // namespace

DepthFrame ApplySensorModel(const SensorModelConfig& config, const IdealDepthImage& ideal, uint64_t seed,
                            int64_t utime) {
  const int width = ideal.intrinsics.width;
  const int height = ideal.intrinsics.height;
  DepthFrame frame;
  frame.utime = utime;
  frame.intrinsics = ideal.intrinsics;
  frame.depth_m.assign(static_cast<size_t>(width) * height, 0.0f);
  frame.intrinsics.fx *= config.intrinsics_scale;
  frame.intrinsics.fy *= config.intrinsics_scale;
  const double wobble_m =
      config.wobble_m * std::sin(2.0 * M_PI * (static_cast<double>(utime) * 1e-6) / config.wobble_period_s);
  const std::vector<float>& z = ideal.depth_m;
  const double cos_start = std::cos(config.grazing_start_deg * kDegToRad);
  const double cos_full = std::cos(config.grazing_full_deg * kDegToRad);
  Rng rng(seed);

  // Depth edges: mark both pixels of every horizontal or vertical pair that
  // jumps by more than edge_jump_m or has a pixel without a return.
  std::vector<uint8_t> edge;
  if (config.edge_dropout_prob > 0.0 || config.mixed_pixel_prob > 0.0) {
    edge.assign(frame.depth_m.size(), 0);
    const float jump = static_cast<float>(config.edge_jump_m);
    auto mark = [&](size_t a, size_t b) {
      if (z[a] <= 0.0f || z[b] <= 0.0f || std::abs(z[a] - z[b]) > jump) edge[a] = edge[b] = 1;
    };
    for (int v = 0; v < height; ++v) {
      const size_t row = static_cast<size_t>(v) * width;
      for (int u = 0; u + 1 < width; ++u) mark(row + u, row + u + 1);
      if (v + 1 < height) {
        for (int u = 0; u < width; ++u) mark(row + u, row + width + u);
      }
    }
  }

  // The angular noise term as a function of cos(theta), tabulated: acos per
  // pixel would cost as much as the rest of the model.
  constexpr int kAngularBins = 4096;
  std::vector<double> angular(kAngularBins + 1);
  for (int b = 0; b <= kAngularBins; ++b) {
    angular[b] = AxialNoiseSigma(config, 1.0, std::acos(static_cast<double>(b) / kAngularBins)) -
                 AxialNoiseSigma(config, 1.0, 0.0);
  }

  for (size_t i = 0; i < frame.depth_m.size(); ++i) {
    const double z_true = z[i];
    if (!(z_true >= config.min_range_m && z_true <= config.max_range_m)) continue;
    if (!ideal.unlit.empty() && ideal.unlit[i] != kLit) continue;
    const double cos_inc = std::clamp(static_cast<double>(ideal.cos_incidence[i]), 0.0, 1.0);
    // Combine the independent losses into one draw.
    double p_graze = 0.0;
    if (cos_inc <= cos_full) {
      p_graze = 1.0;
    } else if (cos_inc < cos_start) {
      p_graze = (cos_start - cos_inc) / (cos_start - cos_full);
    }
    const bool on_edge = !edge.empty() && edge[i];
    const double p_edge = on_edge ? config.edge_dropout_prob : 0.0;
    const double p_keep = (1.0 - p_graze) * (1.0 - p_edge) * (1.0 - config.random_dropout_prob);
    if (p_keep < 1.0 && rng.Uniform() >= p_keep) continue;
    double z_meas = z_true;
    if (on_edge && config.mixed_pixel_prob > 0.0 && rng.Uniform() < config.mixed_pixel_prob) {
      z_meas += rng.Uniform() * (FarthestNeighbourDepth(z, width, height, i) - z_true);
    }
    z_meas = z_meas * config.depth_scale + wobble_m;
    if (config.noise) {
      const double dz = z_true - config.sigma_reference_depth_m;
      const double x = cos_inc * kAngularBins;
      const int b = std::min(static_cast<int>(x), kAngularBins - 1);
      // The table holds the term at z = 1 m; it scales with 1/sqrt(z).
      const double angular_1m = angular[b] + (x - b) * (angular[b + 1] - angular[b]);
      const double sigma =
          config.sigma_base_m + config.sigma_quadratic_m * dz * dz + angular_1m / std::sqrt(z_true);
      z_meas += sigma * rng.Normal();
    }
    if (config.quantize) z_meas = QuantizeDepth(config, ideal.intrinsics.fx, z_meas);
    if (!(z_meas >= config.min_range_m && z_meas <= config.max_range_m)) continue;
    frame.depth_m[i] = static_cast<float>(z_meas);
  }
  return frame;
}

}  // namespace graspfill::synth
