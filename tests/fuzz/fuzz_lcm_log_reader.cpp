// SPDX-License-Identifier: BSD-3-Clause
// The bounded LCM log reader on arbitrary bytes: never reads past the
// file, never allocates more than the file holds, every event inside it.
#include <cstdint>
#include <cstdio>

#include "fuzz_check.hpp"
#include "graspfill/io/lcm_log_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;  // fmemopen refuses empty buffers
  std::FILE* file = fmemopen(const_cast<uint8_t*>(data), size, "rb");
  if (file == nullptr) return 0;
  graspfill::io::LcmLogReader reader(file, static_cast<int64_t>(size), "fuzz");
  graspfill::io::LogEvent event;
  int64_t consumed = 0;
  graspfill::io::LogReadResult result;
  while ((result = reader.Next(&event)) == graspfill::io::LogReadResult::kEvent) {
    consumed +=
        graspfill::io::kLogEventHeaderBytes + static_cast<int64_t>(event.channel.size() + event.data.size());
    FUZZ_CHECK(consumed == reader.offset());
    FUZZ_CHECK(consumed <= static_cast<int64_t>(size));
    FUZZ_CHECK(!event.channel.empty());
  }
  FUZZ_CHECK((result == graspfill::io::LogReadResult::kEnd) == (consumed == static_cast<int64_t>(size)));
  FUZZ_CHECK(reader.Next(&event) == result);  // sticky
  std::fclose(file);
  return 0;
}
