// SPDX-License-Identifier: BSD-3-Clause
// The text the user sees for an exception: the exception's own message,
// except for the standard library's allocation failures, whose what()
// ("std::bad_alloc", "cannot create std::vector larger than max_size()")
// says nothing to the person who ran the command. Shared by the commands
// (rt/cli) and the module's repair verdicts.
#pragma once

#include <exception>
#include <new>
#include <stdexcept>
#include <string>

namespace graspfill::rt {

inline std::string ErrorText(const std::exception& e) {
  if (dynamic_cast<const std::bad_alloc*>(&e) != nullptr) {
    return "out of memory (the input or an option asks for more than this machine has)";
  }
  if (dynamic_cast<const std::length_error*>(&e) != nullptr) {
    // The library's own words name a container's limit (max_size()).
    return "a size beyond what can be allocated (the input or an option asks for more "
           "elements than a container can hold)";
  }
  return e.what();
}

}  // namespace graspfill::rt
