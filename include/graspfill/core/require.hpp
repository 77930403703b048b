// SPDX-License-Identifier: BSD-3-Clause
// How a config's Validate() refuses a value, the same everywhere: a
// std::invalid_argument that says what is wrong, after the config's name
// where the message does not give it ("RefineConfig: gates must be > 0").
#pragma once

#include <stdexcept>
#include <string>

namespace graspfill {

/// Throws std::invalid_argument(what) unless ok.
inline void Require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

/// Throws std::invalid_argument("<config>: <what>") unless ok.
inline void Require(const char* config, bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(std::string(config) + ": " + what);
}

}  // namespace graspfill
