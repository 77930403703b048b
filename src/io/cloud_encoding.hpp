// SPDX-License-Identifier: BSD-3-Clause
// What the cloud writers (PLY, PCD) share: little-endian bytes written
// explicitly, so that a file does not depend on the host; doubles printed
// so they read back exactly; and the check that every per-point field has
// one value per point.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

#include "graspfill/types.hpp"

namespace graspfill::io {

inline void AppendFloat(std::string* out, float value) {
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>(bits >> (8 * i)));
}

inline void AppendInt32(std::string* out, int32_t value) {
  const uint32_t bits = static_cast<uint32_t>(value);
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>(bits >> (8 * i)));
}

inline std::string FormatDouble(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

/// The first of normals, provenance and confidence that is given
/// (non-empty) but not one per point; nullptr when all fit. Callers throw
/// "<field>: not one value per point" in their own terms.
inline const char* FieldNotOnePerPoint(const ObjectCloud& cloud) {
  const size_t n = cloud.points_G.size();
  if (!cloud.normals_G.empty() && cloud.normals_G.size() != n) return "normals";
  if (!cloud.provenance.empty() && cloud.provenance.size() != n) return "provenance";
  if (!cloud.confidence.empty() && cloud.confidence.size() != n) return "confidence";
  return nullptr;
}

/// Throws std::runtime_error "<what> '<path>': <field>: not one value per
/// point" where FieldNotOnePerPoint finds one (the file writers).
inline void CheckOnePerPoint(const ObjectCloud& cloud, const std::string& what, const std::string& path) {
  if (const char* field = FieldNotOnePerPoint(cloud)) {
    throw std::runtime_error(what + " '" + path + "': " + field + ": not one value per point");
  }
}

/// The header text of a frame name: one line.
inline std::string OneLine(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return text;
}

}  // namespace graspfill::io
