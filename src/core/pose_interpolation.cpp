// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/core/pose_interpolation.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <stdexcept>

namespace graspfill {
namespace {

// GCC's own 128-bit integer; __extension__ keeps -Wpedantic quiet about it.
__extension__ typedef __int128 Int128;

}  // namespace

Eigen::Isometry3d InterpolatePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double alpha) {
  const Eigen::Quaterniond qa(a.rotation());
  const Eigen::Quaterniond qb(b.rotation());
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = qa.slerp(alpha, qb).toRotationMatrix();
  out.translation() = (1.0 - alpha) * a.translation() + alpha * b.translation();
  return out;
}

bool IsValidPose(const Eigen::Isometry3d& pose) {
  if (!pose.matrix().allFinite()) return false;
  const Eigen::Matrix3d R = pose.linear();
  return (R * R.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-3 && R.determinant() > 0.0;
}

GripperStateBuffer::GripperStateBuffer(size_t capacity, int64_t max_gap_us)
    : ring_(capacity), max_gap_us_(max_gap_us) {
  if (capacity < 2) throw std::invalid_argument("GripperStateBuffer: capacity < 2");
  // Reserve joint storage once so Push copies without allocating.
  for (GripperState& s : ring_) s.joint_values.reserve(16);
}

bool GripperStateBuffer::Push(const GripperState& state) {
  if (!IsValidPose(state.T_C_G) || !std::isfinite(state.opening_m)) return false;
  if (size_ > 0 && state.utime <= newest_utime()) return false;
  size_t slot;
  if (size_ < ring_.size()) {
    slot = (head_ + size_) % ring_.size();
    ++size_;
  } else {
    slot = head_;  // overwrite the oldest
    head_ = (head_ + 1) % ring_.size();
  }
  GripperState& dst = ring_[slot];
  dst.utime = state.utime;
  dst.T_C_G = state.T_C_G;
  dst.opening_m = state.opening_m;
  dst.joint_values.assign(state.joint_values.begin(), state.joint_values.end());
  return true;
}

int64_t GripperStateBuffer::newest_utime() const { return size_ ? at(size_ - 1).utime : INT64_MIN; }
int64_t GripperStateBuffer::oldest_utime() const { return size_ ? at(0).utime : INT64_MAX; }

PoseLookup GripperStateBuffer::Lookup(int64_t utime, GripperState* out) const {
  if (size_ == 0 || utime > newest_utime()) return PoseLookup::kNotYet;
  if (utime < oldest_utime()) return PoseLookup::kTooEarly;
  // Binary search for the first state at or after utime.
  size_t lo = 0, hi = size_ - 1;
  while (lo < hi) {
    const size_t mid = (lo + hi) / 2;
    if (at(mid).utime < utime)
      lo = mid + 1;
    else
      hi = mid;
  }
  const GripperState& after = at(lo);
  if (after.utime == utime) {
    out->utime = utime;
    out->T_C_G = after.T_C_G;
    out->opening_m = after.opening_m;
    out->joint_values.assign(after.joint_values.begin(), after.joint_values.end());
    return PoseLookup::kOk;
  }
  const GripperState& before = at(lo - 1);  // lo > 0: utime > oldest
  // Differences in 128 bits: states at INT64_MIN and INT64_MAX must not
  // wrap into a small "gap" and interpolate a bogus pose.
  const Int128 gap = static_cast<Int128>(after.utime) - before.utime;
  if (gap > max_gap_us_) return PoseLookup::kGap;
  const double alpha =
      static_cast<double>(static_cast<Int128>(utime) - before.utime) / static_cast<double>(gap);
  out->utime = utime;
  out->T_C_G = InterpolatePose(before.T_C_G, after.T_C_G, alpha);
  out->opening_m = (1.0 - alpha) * before.opening_m + alpha * after.opening_m;
  out->joint_values.resize(before.joint_values.size());
  for (size_t i = 0; i < before.joint_values.size(); ++i) {
    const double b = i < after.joint_values.size() ? after.joint_values[i] : before.joint_values[i];
    out->joint_values[i] = (1.0 - alpha) * before.joint_values[i] + alpha * b;
  }
  return PoseLookup::kOk;
}

}  // namespace graspfill
