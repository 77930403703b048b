// SPDX-License-Identifier: BSD-3-Clause
// The walk over a command line that the commands' parsers share: each
// argument in turn, up to -h or --help.
#pragma once

#include <cstddef>
#include <string>

#include "commands.hpp"

namespace graspfill::cli {

/// Calls on_option(arg, has_value, &i) for each argument args[i] in turn;
/// on_option advances i past a value it takes (args[++*i]). Returns true,
/// reading no further, at -h or --help.
template <typename OnOption>
bool ForEachOption(const Args& args, const OnOption& on_option) {
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") return true;
    on_option(a, i + 1 < args.size(), &i);
  }
  return false;
}

}  // namespace graspfill::cli
