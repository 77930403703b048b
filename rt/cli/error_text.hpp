// SPDX-License-Identifier: BSD-3-Clause
// The text a command prints for an exception (module/error_text.hpp):
// allocation failures in words, every other message as it is.
#pragma once

#include "module/error_text.hpp"

namespace graspfill::cli {

using rt::ErrorText;

}  // namespace graspfill::cli
