// SPDX-License-Identifier: BSD-3-Clause
#include "synth/rig_errors.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "graspfill/core/random.hpp"
#include "graspfill/core/require.hpp"
#include "synth/angles.hpp"

namespace graspfill::synth {
namespace {

// Sub-streams of the scene seed, far from frame indices (renderer) and the
// wobble's stream (scene.cpp).
constexpr uint64_t kHandEyeStream = 0xffffffffff00ULL;
constexpr uint64_t kNoiseStreamBase = 0x7f0000000000ULL;

Eigen::Vector3d RandomUnitVector(Rng* rng) {
  for (;;) {
    const Eigen::Vector3d v(rng->Normal(), rng->Normal(), rng->Normal());
    const double n = v.norm();
    if (n > 1e-9) return v / n;
  }
}

// Isotropic Gaussian vector whose RMS length is `rms`.
Eigen::Vector3d GaussianVector(Rng* rng, double rms) {
  const double sigma = rms / std::sqrt(3.0);
  return Eigen::Vector3d(rng->Normal(), rng->Normal(), rng->Normal()) * sigma;
}

Eigen::Isometry3d FromRotationVector(const Eigen::Vector3d& w, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double angle = w.norm();
  if (angle > 0.0) T.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
  T.translation() = t;
  return T;
}

}  // namespace

void RigErrorConfig::Validate() const {
  Require("RigErrorConfig", std::isfinite(hand_eye_m) && hand_eye_m >= 0.0 && hand_eye_m < 0.1,
          "hand_eye_m must be in [0, 0.1)");
  Require("RigErrorConfig", std::isfinite(hand_eye_deg) && hand_eye_deg >= 0.0 && hand_eye_deg < 45.0,
          "hand_eye_deg must be in [0, 45)");
  Require("RigErrorConfig", std::isfinite(pose_noise_m) && pose_noise_m >= 0.0 && pose_noise_m < 0.1,
          "pose_noise_m must be in [0, 0.1)");
  Require("RigErrorConfig", std::isfinite(pose_noise_deg) && pose_noise_deg >= 0.0 && pose_noise_deg < 45.0,
          "pose_noise_deg must be in [0, 45)");
  Require("RigErrorConfig", clock_offset_us > -1000000 && clock_offset_us < 1000000,
          "clock_offset_us must be within +-1 s");
}

RigErrors::RigErrors(const RigErrorConfig& config, uint64_t seed) : config_(config), seed_(seed) {
  config_.Validate();
  Rng rng(DeriveSeed(seed, kHandEyeStream));
  const Eigen::Vector3d t = RandomUnitVector(&rng) * config_.hand_eye_m;
  const Eigen::Vector3d w = RandomUnitVector(&rng) * (config_.hand_eye_deg * kDegToRad);
  E_C_ = FromRotationVector(w, t);
}

Eigen::Isometry3d RigErrors::StateNoise(int64_t index) const {
  if (config_.pose_noise_m == 0.0 && config_.pose_noise_deg == 0.0) {
    return Eigen::Isometry3d::Identity();
  }
  Rng rng(DeriveSeed(seed_, kNoiseStreamBase + static_cast<uint64_t>(index)));
  const Eigen::Vector3d t = GaussianVector(&rng, config_.pose_noise_m);
  const Eigen::Vector3d w = GaussianVector(&rng, config_.pose_noise_deg * kDegToRad);
  return FromRotationVector(w, t);
}

Eigen::Isometry3d RigErrors::Logged(const Eigen::Isometry3d& T_C_G_true, int64_t index) const {
  return E_C_ * T_C_G_true * StateNoise(index);
}

}  // namespace graspfill::synth
