// SPDX-License-Identifier: BSD-3-Clause
// `--num-threads N` of `replay`, `live` and `repair`: the OpenMP threads of
// each pipeline and repair call (the rig config's compute.num_threads;
// core/openmp_threads.hpp).
#pragma once

#include <string>

#include "graspfill/core/openmp_threads.hpp"
#include "number_parsing.hpp"

namespace graspfill::cli {

/// @throws UsageError outside 0..kMaxOpenMpThreads.
inline int ParseNumThreads(const std::string& text) {
  return ParseInteger<int>("--num-threads", text, 0, kMaxOpenMpThreads);
}

}  // namespace graspfill::cli
