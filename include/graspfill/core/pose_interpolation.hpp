// SPDX-License-Identifier: BSD-3-Clause
// Gripper poses at depth timestamps. Gripper states arrive at their own rate
// (e.g. 100 Hz) and are not aligned with depth frames (e.g. 30 Hz), so the
// pose at a frame's timestamp is interpolated between the two states that
// bracket it: translation linearly, rotation by slerp.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill {

/// Pose between a (alpha = 0) and b (alpha = 1): lerp + slerp.
Eigen::Isometry3d InterpolatePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double alpha);

/// True if every entry of the pose is finite and its rotation is orthonormal.
bool IsValidPose(const Eigen::Isometry3d& pose);

/// Outcome of a lookup in the state buffer.
enum class PoseLookup {
  kOk,        ///< bracketed by two states close enough in time
  kNotYet,    ///< no state at or after the timestamp yet: ask again later
  kTooEarly,  ///< the timestamp is older than every buffered state
  kGap,       ///< the bracketing states are too far apart
};

/// A fixed-capacity ring of gripper states in time order. Push and Lookup
/// never allocate after construction. NOT thread safe.
class GripperStateBuffer {
 public:
  /// @param capacity states kept (at 100 Hz, 256 covers 2.5 s).
  /// @param max_gap_us largest allowed time between the two bracketing
  ///        states (or from an exact state) for an interpolation [us].
  explicit GripperStateBuffer(size_t capacity = 256, int64_t max_gap_us = 50000);

  /// Adds a state. States older than or equal to the newest one are ignored
  /// (returns false), as are states with a non-finite pose.
  bool Push(const GripperState& state);

  /// Pose and opening at `utime`. Writes *out only on kOk.
  PoseLookup Lookup(int64_t utime, GripperState* out) const;

  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  int64_t newest_utime() const;
  int64_t oldest_utime() const;

 private:
  const GripperState& at(size_t i) const {  // 0 = oldest
    return ring_[(head_ + i) % ring_.size()];
  }
  std::vector<GripperState> ring_;
  size_t head_{0};
  size_t size_{0};
  int64_t max_gap_us_;
};

}  // namespace graspfill
