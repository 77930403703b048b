// SPDX-License-Identifier: BSD-3-Clause
// `--config FILE` of `replay` and `live`: the rig config
// (docs/rig-config.md), loaded before the other flags are read so that they win.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "config/rig_config.hpp"
#include "number_parsing.hpp"

namespace graspfill::cli {

/// Loads the file of the one `--config FILE` in `args`, if any.
/// @throws UsageError when --config has no value or is given twice;
///   rt::ConfigError (naming the file, the line and the field) when the
///   file cannot be read or is not a valid rig config. Both exit 2.
inline std::optional<rt::RigConfig> LoadConfigOption(const std::vector<std::string>& args,
                                                     std::string* path) {
  std::optional<std::string> found;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] != "--config") continue;
    if (i + 1 >= args.size()) throw UsageError("--config needs a value");
    if (found) throw UsageError("--config given twice");
    found = args[++i];
  }
  if (!found) return std::nullopt;
  if (path != nullptr) *path = *found;
  return rt::LoadRigConfig(*found);
}

}  // namespace graspfill::cli
