// SPDX-License-Identifier: BSD-3-Clause
#include "config/rig_config_checks.hpp"

#include <charconv>
#include <cmath>
#include <optional>
#include <system_error>

#include "graspfill/io/channel_names.hpp"

namespace graspfill::rt::internal {
namespace {

std::string Expected(const Range& r) {
  return "expected " + FormatNumber(r.min) + ".." + FormatNumber(r.max) +
         (r.unit[0] != '\0' ? std::string(" ") + r.unit : std::string());
}

}  // namespace

std::string FormatNumber(double v) {
  char buffer[64];
  // Shortest round-trip, fixed notation from 1e-4 up (as %g): 0.0005, not 5e-04.
  const auto [ptr, ec] = std::to_chars(buffer, buffer + sizeof(buffer), v, std::chars_format::general);
  if (ec != std::errc()) return std::to_string(v);
  return std::string(buffer, ptr);
}

void CheckRange(const std::string& field, double v, const Range& r) {
  if (!std::isfinite(v) || v < r.min || v > r.max) {
    throw ConfigError(field, field + " '" + FormatNumber(v) + "': out of range, " + Expected(r));
  }
}

// One channel name, as LCM takes it (io/channel_names.hpp).
void CheckChannel(const std::string& field, const std::string& v) {
  if (v.empty()) throw ConfigError(field, field + ": must not be empty");
  if (const std::string defect = io::ChannelNameDefect(v); !defect.empty()) {
    throw ConfigError(field, field + " '" + v + "': " + defect);
  }
}

ConfigError SameChannelError(const std::string& role, const std::string& name,
                             const std::string& other_role) {
  const std::string field = "channels." + role;
  return ConfigError(field, field + " '" + name + "': the same name as channels." + other_role +
                                " (each channel needs its own)");
}

// Every name as LCM takes it, and no two the same.
void CheckChannels(const RigConfig::Channels& channels) {
  const std::optional<io::ChannelNameProblem> problem = io::FindChannelNameProblem(ToChannelNames(channels));
  if (!problem) return;
  CheckChannel("channels." + problem->role, problem->name);
  throw SameChannelError(problem->role, problem->name, problem->same_as);
}

void CheckOneOf(const std::string& field, const std::string& v, const std::vector<std::string>& allowed) {
  for (const std::string& a : allowed) {
    if (v == a) return;
  }
  std::string list;
  for (const std::string& a : allowed) list += (list.empty() ? "" : " or ") + a;
  throw ConfigError(field, field + " '" + v + "': expected " + list);
}

void CheckBox(const std::string& field, const RigConfig::Box& b) {
  static const char* kAxes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    CheckRange(field + ".min_G_m[" + std::to_string(k) + "]", b.min_G_m[k], kBoxM);
    CheckRange(field + ".max_G_m[" + std::to_string(k) + "]", b.max_G_m[k], kBoxM);
  }
  for (int k = 0; k < 3; ++k) {
    if (!(b.min_G_m[k] < b.max_G_m[k])) {
      const std::string f = field + ".max_G_m[" + std::to_string(k) + "]";
      throw ConfigError(f, f + ": must be greater than " + field + ".min_G_m[" + std::to_string(k) + "] (" +
                               kAxes[k] + ": " + FormatNumber(b.min_G_m[k]) + " .. " +
                               FormatNumber(b.max_G_m[k]) + " m is empty)");
    }
  }
}

void CheckPose(const std::string& field, const RigConfig::Pose& p) {
  for (int k = 0; k < 3; ++k) {
    CheckRange(field + ".translation_m[" + std::to_string(k) + "]", p.translation_m[k], kTranslationM);
  }
  double norm2 = 0.0;
  for (int k = 0; k < 4; ++k) {
    CheckRange(field + ".rotation_wxyz[" + std::to_string(k) + "]", p.rotation_wxyz[k], kQuaternion);
    norm2 += p.rotation_wxyz[k] * p.rotation_wxyz[k];
  }
  const double norm = std::sqrt(norm2);
  if (!(std::abs(norm - 1.0) <= kUnitTolerance)) {
    const std::string f = field + ".rotation_wxyz";
    throw ConfigError(f, f + ": not a unit quaternion (norm " + FormatNumber(norm) + "; expected 1 within " +
                             FormatNumber(kUnitTolerance) + ")");
  }
}

void CheckIntrinsics(const std::string& field, const RigConfig::Intrinsics& K) {
  CheckRange(field + ".width_px", K.width_px, kImagePx);
  CheckRange(field + ".height_px", K.height_px, kImagePx);
  CheckRange(field + ".fx_px", K.fx_px, kFocalPx);
  CheckRange(field + ".fy_px", K.fy_px, kFocalPx);
  CheckRange(field + ".cx_px", K.cx_px, kCentrePx);
  CheckRange(field + ".cy_px", K.cy_px, kCentrePx);
}

void CheckSafeBound(const std::string& field, double v) {
  CheckRange(field, v, kSafeBoundM);
  if (v != 0.0 && v < kMinSafeBoundM) {
    throw ConfigError(field, field + " '" + FormatNumber(v) + "': expected 0 (no bound) or " +
                                 FormatNumber(kMinSafeBoundM) + "..0.1 m");
  }
}

}  // namespace graspfill::rt::internal
