// SPDX-License-Identifier: BSD-3-Clause
// The cloud-slice assembler (io/cloud_chunks.hpp) on arbitrary bytes: a
// sequence of messages fed to one assembler, its contract checked after
// each (a known result; a complete cloud non-empty, within
// kMaxChunkedCloudBytes, an object_cloud_t's fingerprint first; a reason
// for every malformed one), and every message that decodes as a whole
// object_cloud_t cut into slices and joined back, permuted with repeats
// (tests/io/cloud_chunks_feed.hpp, shared with the corpus's replay).
//
// Input: records of [length, 2 bytes little-endian][that many bytes],
// until the input ends (a short last record takes what is left).
#include <cstdint>
#include <cstdio>
#include <string>

#include "cloud_chunks_feed.hpp"
#include "fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string broken = graspfill::io::testing::CheckCloudChunkInput(data, size);
  if (!broken.empty()) std::fprintf(stderr, "%s\n", broken.c_str());
  FUZZ_CHECK(broken.empty());
  return 0;
}
