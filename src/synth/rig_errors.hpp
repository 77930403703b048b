// SPDX-License-Identifier: BSD-3-Clause
// What a real rig gets wrong about the gripper poses it logs, for synthetic
// recordings: a hand-eye calibration off by a constant rigid error, noise
// on every gripper state (encoders, arm flex) and a clock offset between
// the robot and the camera. The frames are still rendered from the true
// poses and the ground truth stays in the true G; only the logged gripper
// states carry the errors. All seeded (same config and seed, same errors),
// all off by default.
//
// A logged state stamped `utime` holds
//   T_C_G_logged = E_C * T_C_G_true(utime + clock_offset) * N_k
// where E_C is the hand-eye error (a constant rigid motion of the camera
// frame: a wrong T_C_B moves every pose the same way in C) and N_k the
// state's own noise (in G, where the arm's kinematics err).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>

namespace graspfill::synth {

struct RigErrorConfig {
  /// Hand-eye error: a translation of exactly this length [m] in a random
  /// direction and a rotation of exactly this angle [deg] about a random
  /// axis, both in C. 0: none.
  double hand_eye_m{0.0};
  double hand_eye_deg{0.0};
  /// Per gripper state: a random translation and rotation in G, isotropic
  /// Gaussian with these RMS magnitudes [m], [deg]. 0: none.
  double pose_noise_m{0.0};
  double pose_noise_deg{0.0};
  /// The logged gripper-state timestamps run this far behind the depth
  /// frames' clock: a state stamped t holds the true pose at t + offset
  /// [us]. 0: none.
  int64_t clock_offset_us{0};

  bool any() const {
    return hand_eye_m != 0.0 || hand_eye_deg != 0.0 || pose_noise_m != 0.0 || pose_noise_deg != 0.0 ||
           clock_offset_us != 0;
  }
  /// Throws std::invalid_argument naming the bad field (negative sizes,
  /// angles >= 45 deg, translations >= 0.1 m, |offset| >= 1 s).
  void Validate() const;
};

class RigErrors {
 public:
  /// Draws the hand-eye error from `seed` (a sub-stream of it; the noise of
  /// state k is drawn from another, so it does not depend on the order the
  /// states are asked for).
  RigErrors(const RigErrorConfig& config, uint64_t seed);

  const RigErrorConfig& config() const { return config_; }
  /// The hand-eye error E_C (maps true camera coordinates to the logged
  /// ones: T_C_G_logged = E_C * T_C_G_true, before noise).
  const Eigen::Isometry3d& hand_eye_error() const { return E_C_; }
  /// The noise N_k of gripper state `index` (identity without noise).
  Eigen::Isometry3d StateNoise(int64_t index) const;
  /// The true time [us] whose pose a state stamped `logged_utime` holds.
  int64_t TrueUtime(int64_t logged_utime) const { return logged_utime + config_.clock_offset_us; }
  /// The logged pose of state `index` from its true pose.
  Eigen::Isometry3d Logged(const Eigen::Isometry3d& T_C_G_true, int64_t index) const;

 private:
  RigErrorConfig config_;
  uint64_t seed_;
  Eigen::Isometry3d E_C_{Eigen::Isometry3d::Identity()};
};

}  // namespace graspfill::synth
