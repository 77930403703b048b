// SPDX-License-Identifier: BSD-3-Clause
#include "wire.hpp"

#include <climits>
#include <cmath>
#include <cstdio>

namespace graspfill::io::wire {
namespace {

// Tolerance on |q| before a quaternion counts as not a rotation.
constexpr double kUnitQuaternionTolerance = 1e-3;

}  // namespace

MessageError& FailureReason() {
  thread_local MessageError reason = MessageError::kNone;
  return reason;
}

void SetError(std::string* error, const std::string& message, MessageError reason) {
  FailureReason() = reason;
  if (error != nullptr) *error = message;
}

std::string FormatLimit(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

// `text` fit for a one-line message: bytes outside printable ASCII as \xHH,

std::string Printable(const std::string& text, size_t max_chars) {
  std::string out;
  for (size_t i = 0; i < text.size() && i < max_chars; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02x", c);
      out += hex;
    }
  }
  if (text.size() > max_chars) out += "...";
  return out;
}

bool UtimeInRange(const char* type, int64_t utime, std::string* error) {
  if (utime < 0 || utime > kMaxUtime) {
    SetError(error,
             std::string(type) + ": utime " + std::to_string(utime) + " outside 0.." +
                 std::to_string(kMaxUtime) + " us",
             MessageError::kBadTimestamp);
    return false;
  }
  return true;
}

bool AllFinite(const double* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

bool PoseFromWire(const char* type, const double position[3], const double orientation[4],
                  Eigen::Isometry3d* T, std::string* error) {
  if (!AllFinite(position, 3) || !AllFinite(orientation, 4)) {
    SetError(error, std::string(type) + ": pose is not finite", MessageError::kBadPose);
    return false;
  }
  Eigen::Quaterniond q(orientation[0], orientation[1], orientation[2], orientation[3]);
  const double norm = q.norm();
  if (std::abs(norm - 1.0) > kUnitQuaternionTolerance) {
    SetError(
        error,
        std::string(type) + ": orientation is not a unit quaternion (|q| = " + std::to_string(norm) + ")",
        MessageError::kBadPose);
    return false;
  }
  q.normalize();
  T->setIdentity();
  T->linear() = q.toRotationMatrix();
  T->translation() = Eigen::Vector3d(position[0], position[1], position[2]);
  return true;
}

void PoseToWire(const Eigen::Isometry3d& T, double position[3], double orientation[4]) {
  Eigen::Quaterniond q(T.rotation());
  q.normalize();
  for (int i = 0; i < 3; ++i) position[i] = T.translation()[i];
  orientation[0] = q.w();
  orientation[1] = q.x();
  orientation[2] = q.y();
  orientation[3] = q.z();
}

bool CheckBuffer(const void* data, size_t size, const void* out, const char* type, std::string* error) {
  if (out == nullptr) {
    SetError(error, std::string(type) + ": null output");
    return false;
  }
  if (data == nullptr && size != 0) {
    SetError(error, std::string(type) + ": null data");
    return false;
  }
  if (size > static_cast<size_t>(INT_MAX)) {
    SetError(error, std::string(type) + ": message too large");
    return false;
  }
  return true;
}

}  // namespace graspfill::io::wire
