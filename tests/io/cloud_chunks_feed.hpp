// SPDX-License-Identifier: BSD-3-Clause
// Feeds a CloudChunkAssembler a sequence of messages as the bus would and
// checks what it promises whatever comes (cloud_chunks.hpp), and that a
// cloud cut by EncodeCloudChunks joins back to the same bytes in any order
// with repeats. Shared by the fuzzer (tests/fuzz/fuzz_cloud_chunks.cpp)
// and the replay of its corpus (fuzz_regressions_test.cc).
//
// Input: records of [length, 2 bytes little-endian][that many bytes],
// until the input ends (a short last record takes what is left).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <graspfill/object_cloud_t.hpp>

#include "graspfill/io/cloud_chunks.hpp"
#include "graspfill/io/messages.hpp"

namespace graspfill::io::testing {

namespace cloud_chunks_detail {

// Deterministic choices from the message itself (FNV-1a, then splitmix64):
// the same input always makes the same slices and order.
inline uint64_t Fnv1a(const uint8_t* data, size_t size) {
  uint64_t h = 14695981039346656037ull;
  for (size_t i = 0; i < size; ++i) h = (h ^ data[i]) * 1099511628211ull;
  return h;
}
inline uint64_t SplitMix(uint64_t* state) {
  uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

inline bool StartsWithCloudFingerprint(const std::vector<uint8_t>& bytes) {
  if (bytes.size() < 8) return false;
  const auto hash = static_cast<uint64_t>(graspfill::object_cloud_t::getHash());
  for (size_t i = 0; i < 8; ++i) {
    if (bytes[i] != static_cast<uint8_t>(hash >> (56 - 8 * i))) return false;
  }
  return true;
}

inline const char* Name(CloudChunkAssembler::Result r) {
  switch (r) {
    case CloudChunkAssembler::Result::kComplete:
      return "complete";
    case CloudChunkAssembler::Result::kPending:
      return "pending";
    case CloudChunkAssembler::Result::kRepeat:
      return "repeat";
    case CloudChunkAssembler::Result::kMalformed:
      return "malformed";
  }
  return nullptr;
}

// A message that decodes as a whole object_cloud_t: its encoding cut into
// 2..16 slices, fed to a fresh assembler in a permuted order with repeats
// of slices already fed; only the last new slice completes it, with
// exactly those bytes; a repeat after that is a repeat.
inline std::string CheckRoundTrip(const uint8_t* message, size_t size) {
  ObjectCloud decoded;
  std::string error;
  if (!DecodeObjectCloud(message, size, &decoded, &error)) return "";
  const std::vector<uint8_t> cloud = EncodeObjectCloud(decoded);
  if (cloud.size() > kMaxChunkedCloudBytes) return "";
  uint64_t rng = Fnv1a(message, size);
  const size_t wanted = 2 + SplitMix(&rng) % 15;
  const size_t max_slice_bytes = (cloud.size() + wanted - 1) / wanted;
  const std::vector<std::vector<uint8_t>> slices = EncodeCloudChunks(cloud, max_slice_bytes);
  if (slices.size() < 2) return "a cloud of " + std::to_string(cloud.size()) + " bytes cut in one slice";
  std::vector<size_t> order(slices.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  for (size_t i = order.size() - 1; i > 0; --i) std::swap(order[i], order[SplitMix(&rng) % (i + 1)]);
  CloudChunkAssembler assembler;
  using Result = CloudChunkAssembler::Result;
  const auto add = [&](size_t slice) { return assembler.Add(slices[slice].data(), slices[slice].size()); };
  for (size_t i = 0; i < order.size(); ++i) {
    while (i > 0 && SplitMix(&rng) % 3 == 0) {  // a repeat of one already fed
      const size_t again = order[SplitMix(&rng) % i];
      const Result r = add(again);
      if (r != Result::kRepeat) return std::string("a repeated slice gave ") + Name(r);
    }
    const Result r = add(order[i]);
    const Result expected = i + 1 < order.size() ? Result::kPending : Result::kComplete;
    if (r != expected) {
      return "slice " + std::to_string(order[i]) + ", new and " + std::to_string(i + 1) + " of " +
             std::to_string(order.size()) + ", gave " + Name(r) + ", not " + Name(expected);
    }
  }
  if (assembler.cloud() != cloud) return "the joined cloud differs from the cut one";
  if (assembler.dropped_unfinished() != 0) return "a cloud dropped while joining one cloud";
  const Result after = add(order[SplitMix(&rng) % order.size()]);
  if (after != Result::kRepeat) return std::string("a slice of the completed cloud gave ") + Name(after);
  return "";
}

}  // namespace cloud_chunks_detail

/// "" when a CloudChunkAssembler fed the input's records kept its contract
/// and every record that decodes as an object_cloud_t round trips through
/// slices; else what broke (the first thing).
inline std::string CheckCloudChunkInput(const uint8_t* data, size_t size) {
  using namespace cloud_chunks_detail;
  using Result = CloudChunkAssembler::Result;
  CloudChunkAssembler assembler;
  size_t at = 0;
  for (int64_t fed = 1; at < size; ++fed) {
    size_t length = 0;
    if (at + 2 <= size) length = data[at] | (static_cast<size_t>(data[at + 1]) << 8);
    at = at + 2 <= size ? at + 2 : size;
    if (length > size - at) length = size - at;
    const uint8_t* message = data + at;
    at += length;
    const std::string where = "message " + std::to_string(fed) + " (" + std::to_string(length) + " bytes): ";
    const int64_t dropped_before = assembler.dropped_unfinished();
    std::string why;
    const Result r = assembler.Add(message, length, &why);
    if (Name(r) == nullptr) return where + "a result outside the enum";
    if (r == Result::kComplete) {
      const std::vector<uint8_t>& cloud = assembler.cloud();
      if (cloud.empty() || cloud.size() > kMaxChunkedCloudBytes) {
        return where + "complete with " + std::to_string(cloud.size()) + " bytes";
      }
      if (!StartsWithCloudFingerprint(cloud)) return where + "complete, not an object_cloud_t's fingerprint";
    }
    if (r == Result::kMalformed && why.empty()) return where + "malformed without a reason";
    const int64_t dropped = assembler.dropped_unfinished() - dropped_before;
    if (dropped != 0 && dropped != 1)
      return where + "dropped_unfinished went up by " + std::to_string(dropped);
    const std::string round_trip = CheckRoundTrip(message, length);
    if (!round_trip.empty()) return where + round_trip;
  }
  return "";
}

}  // namespace graspfill::io::testing
