// SPDX-License-Identifier: BSD-3-Clause
// A model in one-datagram slices (object_cloud_chunk_t, lcmtypes/
// object_cloud_chunk_t.lcm): on LCM's UDP multicast a whole object_cloud_t
// of two or three 64 kB fragments was now and then lost at a subscriber
// keeping the kernel's default receive buffer, when the bus's other traffic
// (depth frames) had filled it; one datagram at a time, paced, gets in
// (docs/measurements/2026-12-06-cloud-delivery.md). Pure functions and a
// plain class over bytes: the pacing is rt's (rt/sinks/cloud_pacer.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace graspfill::io {

/// The most bytes of the cloud one slice carries: with its 48-byte header
/// and LCM's (8 bytes and the channel name) it stays one UDP datagram
/// (LCM sends up to 65,499 bytes unfragmented).
constexpr size_t kCloudSliceBytes = 60000;
/// The largest encoded cloud the slices may describe [bytes] (an assembler
/// allocates this much at most for the cloud it joins, on a slice's word).
constexpr size_t kMaxChunkedCloudBytes = size_t{64} << 20;

/// Cuts `cloud` (EncodeObjectCloud's bytes) into object_cloud_chunk_t
/// messages of at most `max_slice_bytes` of it each, in equal slices (the
/// last one shorter), in order. Deterministic.
/// @throws std::invalid_argument if `cloud` is not an object_cloud_t
///   (fingerprint), is larger than kMaxChunkedCloudBytes, or
///   max_slice_bytes is 0.
std::vector<std::vector<uint8_t>> EncodeCloudChunks(const std::vector<uint8_t>& cloud,
                                                    size_t max_slice_bytes = kCloudSliceBytes);

/// Joins the messages of a cloud channel back into whole object_cloud_t
/// bytes: object_cloud_chunk_t slices (in any order, repeats ignored) and
/// whole object_cloud_t messages (passed through), so one reader serves the
/// live bus and logs alike.
///
/// One cloud is joined at a time: a slice of another cloud drops an
/// unfinished one (counted in dropped_unfinished()), as a publisher sends
/// one cloud's slices before the next's. Malformed messages are rejected
/// without allocating more than kMaxChunkedCloudBytes. Starting another
/// cloud costs what the dropped one received, not the size its header
/// claims (the buffers only grow), so slice headers alone cannot keep the
/// reader busy. Not thread safe.
class CloudChunkAssembler {
 public:
  enum class Result {
    kComplete,   ///< cloud() holds a whole object_cloud_t
    kPending,    ///< a slice was kept; the cloud is not whole yet
    kRepeat,     ///< a slice already had (or of the cloud just completed): ignored
    kMalformed,  ///< neither type, inconsistent sizes, or a joined cloud whose CRC differs: *why
  };

  /// Takes one message's payload (LCM's data, without channel).
  Result Add(const void* data, size_t size, std::string* why = nullptr);

  /// The whole encoded object_cloud_t after Add gave kComplete; valid until
  /// the next Add.
  const std::vector<uint8_t>& cloud() const { return cloud_; }

  /// Unfinished clouds dropped because a slice of another one came.
  int64_t dropped_unfinished() const { return dropped_unfinished_; }

 private:
  struct Key {
    int64_t utime{0};
    int64_t seq{0};
    uint32_t num_bytes{0};
    uint32_t crc32{0};
    uint32_t num_chunks{0};
    bool operator==(const Key& o) const {
      return utime == o.utime && seq == o.seq && num_bytes == o.num_bytes && crc32 == o.crc32 &&
             num_chunks == o.num_chunks;
    }
  };

  // Forgets the pending cloud's slices in time proportional to how many came.
  void ClearHad();

  Key pending_key_;
  bool pending_{false};              // a cloud is being joined
  std::vector<uint64_t> had_bits_;   // per slice of the pending cloud: a bit, set once had
  std::vector<uint32_t> had_words_;  // the words of had_bits_ not zero (the others are)
  uint32_t slices_missing_{0};
  std::vector<uint8_t> joining_;  // the pending cloud's bytes, at its front
  Key completed_key_;             // the cloud last completed: its repeats are ignored
  bool completed_{false};
  std::vector<uint8_t> cloud_;  // the complete cloud
  int64_t dropped_unfinished_{0};
};

}  // namespace graspfill::io
