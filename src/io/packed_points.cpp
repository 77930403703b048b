// SPDX-License-Identifier: BSD-3-Clause
#include "packed_points.hpp"

#include "cloud_encoding.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace graspfill::io {
namespace {

constexpr double kMaxSteps = 32767.0;  // |q| of an int16
// zlib's deflate compresses at most ~1032:1: a stream claiming more bytes
// than that is refused before anything is allocated for it.
constexpr size_t kMaxInflateRatio = 1100;

void PutInt16(uint8_t* at, int16_t v) {
  const auto u = static_cast<uint16_t>(v);
  at[0] = static_cast<uint8_t>(u & 0xff);
  at[1] = static_cast<uint8_t>(u >> 8);
}

int16_t GetInt16(const uint8_t* at) {
  return static_cast<int16_t>(static_cast<uint16_t>(at[0] | (at[1] << 8)));
}

// Per thread, reused: published clouds are decoded at the bus's rate.
std::vector<uint8_t>& PackedBytesScratch() {
  thread_local std::vector<uint8_t> bytes;
  return bytes;
}

}  // namespace

size_t PackedSize(size_t num_points, bool has_normals) {
  return num_points * (6 + (has_normals ? 3 : 0) + 2);
}

PackedPoints PackPoints(const ObjectCloud& cloud) {
  const size_t n = cloud.points_G.size();
  if (const char* field = FieldNotOnePerPoint(cloud)) {
    throw std::invalid_argument(std::string("object_cloud_t: ") + field + ": not one value per point");
  }
  PackedPoints packed;
  packed.has_normals = !cloud.normals_G.empty();
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d p = cloud.points_G[i].cast<double>();
    if (!p.allFinite())
      throw std::invalid_argument("object_cloud_t: point " + std::to_string(i) + " is not finite");
    lo = i == 0 ? p : lo.cwiseMin(p);
    hi = i == 0 ? p : hi.cwiseMax(p);
  }
  // The step: 50 um times a power of two, and the origin on its grid, so
  // that packing a decoded cloud again gives the same points (a model
  // re-published by a relay is not moved again). The origin's rounding
  // moves the centre by half a step at most: one step of margin.
  const double half_extent = 0.5 * (hi - lo).maxCoeff();
  packed.step_m = kPositionStepM;
  while (half_extent / packed.step_m > kMaxSteps - 1.0 && std::isfinite(packed.step_m)) packed.step_m *= 2.0;
  const Eigen::Vector3d origin = (0.5 * (lo + hi) / packed.step_m).array().round() * packed.step_m;
  for (int k = 0; k < 3; ++k) packed.origin[k] = origin[k];

  std::vector<uint8_t>& raw = PackedBytesScratch();
  raw.assign(PackedSize(n, packed.has_normals), 0);
  uint8_t* at = raw.data();
  for (int k = 0; k < 3; ++k) {
    for (size_t i = 0; i < n; ++i, at += 2) {
      const double q = std::round((cloud.points_G[i][k] - origin[k]) / packed.step_m);
      PutInt16(at, static_cast<int16_t>(std::clamp(q, -kMaxSteps, kMaxSteps)));
    }
  }
  if (packed.has_normals) {
    for (int k = 0; k < 3; ++k) {
      for (size_t i = 0; i < n; ++i) {
        const float v = cloud.normals_G[i][k];
        if (!std::isfinite(v))
          throw std::invalid_argument("object_cloud_t: normal " + std::to_string(i) + " is not finite");
        *at++ = static_cast<uint8_t>(static_cast<int8_t>(std::lround(std::clamp(v, -1.0f, 1.0f) * 127.0f)));
      }
    }
  }
  for (size_t i = 0; i < n; ++i) {
    *at++ = static_cast<uint8_t>(cloud.provenance.empty() ? Provenance::kObserved : cloud.provenance[i]);
  }
  for (size_t i = 0; i < n; ++i) {
    const float c = cloud.confidence.empty() ? 1.0f : cloud.confidence[i];
    // NaN is refused as out of [0, 1], as the decoder refuses it.
    if (!(c >= 0.0f && c <= 1.0f)) throw std::invalid_argument("object_cloud_t: confidence outside [0, 1]");
    // The nearest byte, halves down: 0.5, a coin flip, packs to 127 and
    // reads back below 0.5, so every reader keeps which side of 0.5 a
    // point is on (above it: the repair stands behind the point).
    *at++ = static_cast<uint8_t>(std::ceil(c * 255.0f - 0.5f));
  }
  // Level 1: the bundled recording's model packs to 132 kB in 4 ms, where
  // the default level 6 gives 127 kB in 10 ms (zlib 1.2.13, this project's
  // 2-core machines).
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  packed.deflated.resize(size);
  if (compress2(packed.deflated.data(), &size, raw.data(), static_cast<uLong>(raw.size()), Z_BEST_SPEED) !=
      Z_OK) {
    throw std::runtime_error("object_cloud_t: zlib could not deflate the points");
  }
  packed.deflated.resize(size);
  return packed;
}

bool UnpackPoints(const double origin[3], double step_m, bool has_normals, size_t num_points,
                  const uint8_t* deflated, size_t deflated_size, ObjectCloud* out, std::string* why) {
  if (!(step_m >= kPositionStepM && std::isfinite(step_m)) || !std::isfinite(origin[0]) ||
      !std::isfinite(origin[1]) || !std::isfinite(origin[2])) {
    *why = "a non-finite origin or a step below " + std::to_string(kPositionStepM) + " m";
    return false;
  }
  const size_t size = PackedSize(num_points, has_normals);
  if (size / kMaxInflateRatio > deflated_size) {
    *why = std::to_string(num_points) + " points cannot be in " + std::to_string(deflated_size) +
           " packed bytes";
    return false;
  }
  std::vector<uint8_t>& raw = PackedBytesScratch();
  raw.resize(size + 1);  // one more: a stream that inflates past `size` fills it
  uLongf inflated = static_cast<uLongf>(raw.size());
  uLong consumed = static_cast<uLong>(deflated_size);
  const int rc = uncompress2(raw.data(), &inflated, deflated, &consumed);
  if (rc == Z_BUF_ERROR && inflated == raw.size()) {
    *why = "the points inflate to more than the " + std::to_string(size) + " bytes of " +
           std::to_string(num_points) + " points";
    return false;
  }
  if (rc != Z_OK || consumed != deflated_size) {
    *why = std::string("the packed points are not a whole zlib stream (") + zError(rc) + ")";
    return false;
  }
  if (inflated != size) {
    *why = "the points inflate to " + std::to_string(inflated) + " bytes, not the " + std::to_string(size) +
           " of " + std::to_string(num_points) + " points";
    return false;
  }
  const uint8_t* at = raw.data();
  out->points_G.resize(num_points);
  for (int k = 0; k < 3; ++k) {
    for (size_t i = 0; i < num_points; ++i, at += 2) {
      const float v = static_cast<float>(origin[k] + step_m * GetInt16(at));
      if (!std::isfinite(v)) {
        *why = "non-finite point coordinate (point " + std::to_string(i) + ")";
        return false;
      }
      out->points_G[i][k] = v;
    }
  }
  out->normals_G.resize(has_normals ? num_points : 0);
  if (has_normals) {
    for (int k = 0; k < 3; ++k) {
      for (size_t i = 0; i < num_points; ++i) out->normals_G[i][k] = static_cast<int8_t>(*at++) / 127.0f;
    }
    for (Eigen::Vector3f& normal : out->normals_G) {
      const float norm = normal.norm();
      if (norm > 0.0f) normal /= norm;
    }
  }
  out->provenance.resize(num_points);
  for (size_t i = 0; i < num_points; ++i, ++at) {
    if (*at > static_cast<uint8_t>(Provenance::kSymmetry)) {
      *why = "unknown provenance " + std::to_string(static_cast<int>(static_cast<int8_t>(*at)));
      return false;
    }
    out->provenance[i] = static_cast<Provenance>(*at);
  }
  out->confidence.resize(num_points);
  for (size_t i = 0; i < num_points; ++i) out->confidence[i] = *at++ / 255.0f;
  return true;
}

}  // namespace graspfill::io
