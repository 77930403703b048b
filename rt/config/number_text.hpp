// SPDX-License-Identifier: BSD-3-Clause
// Strict reading of a number written as text, for the rig config's fields
// and the CLI's options alike: the whole text must be the number (no
// leading blanks or '+', no trailing characters), finite, and inside the
// field's range; anything else is std::invalid_argument naming the field,
// the text and what was expected.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>

namespace graspfill::rt {

namespace internal {

inline std::string FormatBound(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

}  // namespace internal

/// A real number in [min, max] (e.g. `ReadNumber("--voxel-m", "0.002",
/// 0.0005, 0.02, "m")`). `unit` ("m", "s", ...) only words the message.
/// @throws std::invalid_argument "--voxel-m 'abc': not a number" or
///   "--voxel-m '1.5': out of range, expected 0.0005..0.02 m".
inline double ReadNumber(const std::string& name, const std::string& text, double min, double max,
                         const std::string& unit = "") {
  double value = 0.0;
  const char* begin = text.data();
  const char* end = begin + text.size();
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  const std::string quoted = name + " '" + text + "'";
  if (text.empty() || ptr != end || ec == std::errc::invalid_argument) {
    throw std::invalid_argument(quoted + ": not a number");
  }
  const std::string expected =
      internal::FormatBound(min) + ".." + internal::FormatBound(max) + (unit.empty() ? "" : " " + unit);
  if (ec == std::errc::result_out_of_range || !std::isfinite(value) || value < min || value > max) {
    throw std::invalid_argument(quoted + ": out of range, expected " + expected);
  }
  return value;
}

/// An integer in [min, max], decimal digits with an optional '-'.
/// @throws std::invalid_argument "--publish-every 'x': not an integer" or
///   "...: out of range, expected 0..100000".
template <typename Int>
Int ReadInteger(const std::string& name, const std::string& text, Int min, Int max) {
  static_assert(std::numeric_limits<Int>::is_integer, "ReadInteger: an integer type");
  Int value = 0;
  const char* begin = text.data();
  const char* end = begin + text.size();
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  const std::string quoted = name + " '" + text + "'";
  if (text.empty() || ec == std::errc::invalid_argument || ptr != end) {
    throw std::invalid_argument(quoted + ": not an integer");
  }
  if (ec == std::errc::result_out_of_range || value < min || value > max) {
    throw std::invalid_argument(quoted + ": out of range, expected " + std::to_string(min) + ".." +
                                std::to_string(max));
  }
  return value;
}

}  // namespace graspfill::rt
