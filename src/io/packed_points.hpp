// SPDX-License-Identifier: BSD-3-Clause
// The per-point arrays of object_cloud_t, packed so that a model fits LCM's
// default UDP receive buffers: positions as int16 steps of 50 um (times a
// power of two for clouds over 3.3 m) about an origin, normals and confidence in 8 bits, the whole deflated
// by zlib. The layout is object_cloud_t.lcm's; this is its one writer and reader in C++.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::io {

/// The smallest position step [m] (object_cloud_t.lcm: 50 um): far
/// below the fused cloud's noise, and 65535 steps still span 3.3 m.
constexpr double kPositionStepM = 5e-5;

struct PackedPoints {
  double origin[3]{0.0, 0.0, 0.0};  ///< point = origin + step_m * q [m]
  double step_m{kPositionStepM};
  bool has_normals{false};
  std::vector<uint8_t> deflated;  ///< zlib stream of the arrays
};

/// Packs the cloud's points, normals (if any), provenance (kObserved where
/// empty) and confidence (1 where empty). Deterministic.
/// @throws std::invalid_argument on a non-finite point or normal, a
///   confidence outside [0, 1], or normals, provenance or confidence given
///   but not one per point.
PackedPoints PackPoints(const ObjectCloud& cloud);

/// The inflated size of `num_points` packed points [bytes].
size_t PackedSize(size_t num_points, bool has_normals);

/// Unpacks `deflated` into out's points_G, normals_G (empty unless
/// has_normals), provenance and confidence. The stream must inflate to
/// exactly PackedSize bytes, with provenance values 0..2; nothing is
/// allocated for a count the stream cannot hold (zlib inflates at most
/// ~1032:1).
/// @return false (and *why) on a malformed stream or values out of range.
bool UnpackPoints(const double origin[3], double step_m, bool has_normals, size_t num_points,
                  const uint8_t* deflated, size_t deflated_size, ObjectCloud* out, std::string* why);

}  // namespace graspfill::io
