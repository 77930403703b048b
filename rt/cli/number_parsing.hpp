// Strict parsing of the commands' numeric options: the whole text must be
// the number (no leading blanks or '+', no trailing characters), finite, and
// inside the option's range; anything else is a usage error that names the
// option, the text and what was expected.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>

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

namespace internal {

inline std::string FormatBound(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

}  // namespace internal

/// A real number in [min, max] (e.g. `ParseDouble("--voxel-m", "0.002",
/// 0.0005, 0.02, "m")`). `unit` ("m", "s", ...) only words the message.
/// @throws UsageError "--voxel-m 'abc': not a number" or "--voxel-m '1.5':
///   out of range, expected 0.0005..0.02 m".
inline double ParseDouble(const std::string& option, const std::string& text, double min,
                          double max, const std::string& unit = "") {
  double value = 0.0;
  const char* begin = text.data();
  const char* end = begin + text.size();
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  const std::string quoted = option + " '" + text + "'";
  if (text.empty() || ptr != end || ec == std::errc::invalid_argument) {
    throw UsageError(quoted + ": not a number");
  }
  const std::string expected = internal::FormatBound(min) + ".." + internal::FormatBound(max) +
                               (unit.empty() ? "" : " " + unit);
  if (ec == std::errc::result_out_of_range || !std::isfinite(value) || value < min ||
      value > max) {
    throw UsageError(quoted + ": out of range, expected " + expected);
  }
  return value;
}

/// An integer in [min, max], decimal digits with an optional '-'.
/// @throws UsageError "--publish-every 'x': not an integer" or "...: out of
///   range, expected 0..100000".
template <typename Int>
Int ParseInteger(const std::string& option, const std::string& text, Int min, Int max) {
  static_assert(std::numeric_limits<Int>::is_integer, "ParseInteger: an integer type");
  Int value = 0;
  const char* begin = text.data();
  const char* end = begin + text.size();
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  const std::string quoted = option + " '" + text + "'";
  if (text.empty() || ec == std::errc::invalid_argument || ptr != end) {
    throw UsageError(quoted + ": not an integer");
  }
  if (ec == std::errc::result_out_of_range || value < min || value > max) {
    throw UsageError(quoted + ": out of range, expected " + std::to_string(min) + ".." +
                     std::to_string(max));
  }
  return value;
}

}  // namespace graspfill::cli
