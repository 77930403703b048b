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

/// Throws std::runtime_error "<what> '<path>': <field>: not one value per
/// point" where normals, provenance or confidence are given (non-empty) but
/// not one per point.
inline void CheckOnePerPoint(const ObjectCloud& cloud, const std::string& what,
                             const std::string& path) {
  const size_t n = cloud.points_G.size();
  const auto check = [&](size_t size, const char* field) {
    if (size != 0 && size != n) {
      throw std::runtime_error(what + " '" + path + "': " + field + ": not one value per point");
    }
  };
  check(cloud.normals_G.size(), "normals");
  check(cloud.provenance.size(), "provenance");
  check(cloud.confidence.size(), "confidence");
}

/// The header text of a frame name: one line.
inline std::string OneLine(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return text;
}

}  // namespace graspfill::io
