// SPDX-License-Identifier: BSD-3-Clause
// module_status_t decoder on arbitrary bytes, with an encode round trip.
#include <cstdint>
#include <string>

#include "fuzz_check.hpp"
#include "graspfill/io/messages.hpp"

using namespace graspfill;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  io::ModuleStatus status;
  std::string error;
  if (!io::DecodeModuleStatus(data, size, &status, &error)) return 0;
  const std::vector<uint8_t> bytes = io::EncodeModuleStatus(status);
  io::ModuleStatus back;
  FUZZ_CHECK(io::DecodeModuleStatus(bytes.data(), bytes.size(), &back, &error));
  FUZZ_CHECK(back.utime == status.utime && back.frames_in == status.frames_in &&
             back.frames_used == status.frames_used && back.frames_skipped == status.frames_skipped &&
             back.frames_dropped == status.frames_dropped && back.state == status.state &&
             back.bad_messages.by_reason == status.bad_messages.by_reason);
  return 0;
}
