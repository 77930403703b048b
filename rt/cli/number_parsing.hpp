// SPDX-License-Identifier: BSD-3-Clause
// Strict parsing of the commands' numeric options (config/number_text.hpp,
// which the rig config reads its fields with too): the whole text must be
// the number, finite, and inside the option's range; anything else is a
// usage error that names the option, the text and what was expected.
#pragma once

#include <stdexcept>
#include <string>

#include "config/number_text.hpp"
#include "graspfill/io/session_limits.hpp"

namespace graspfill::cli {

/// The TSDF voxel edges the commands accept [m] (--voxel-m, and a session
/// description's voxel_m): session_limits.hpp's.
constexpr double kMinVoxelM = io::kMinVoxelM;
constexpr double kMaxVoxelM = io::kMaxVoxelM;

/// A usage error: the command prints it with its usage text and exits 2.
struct UsageError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

/// A real number in [min, max] (e.g. `ParseDouble("--voxel-m", "0.002",
/// 0.0005, 0.02, "m")`): rt::ReadNumber's, its error a usage error.
/// @throws UsageError "--voxel-m 'abc': not a number" or "--voxel-m '1.5':
///   out of range, expected 0.0005..0.02 m".
inline double ParseDouble(const std::string& option, const std::string& text, double min, double max,
                          const std::string& unit = "") {
  try {
    return rt::ReadNumber(option, text, min, max, unit);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

/// An integer in [min, max], decimal digits with an optional '-':
/// rt::ReadInteger's, its error a usage error.
/// @throws UsageError "--publish-every 'x': not an integer" or "...: out of
///   range, expected 0..100000".
template <typename Int>
Int ParseInteger(const std::string& option, const std::string& text, Int min, Int max) {
  try {
    return rt::ReadInteger<Int>(option, text, min, max);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

}  // namespace graspfill::cli
