// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/io/cloud_chunks.hpp"

#include <zlib.h>
#include <graspfill/object_cloud_chunk_t.hpp>
#include <graspfill/object_cloud_t.hpp>

#include <algorithm>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace graspfill::io {

namespace {

// object_cloud_chunk_t's fixed part: fingerprint, utime, seq, six int32.
constexpr size_t kChunkHeaderBytes = 8 + 8 + 8 + 6 * 4;
// object_cloud_t begins with its fingerprint, then utime and seq.
constexpr size_t kCloudHeadBytes = 8 + 8 + 8;

uint64_t ReadBigEndian(const uint8_t* p, size_t n) {
  uint64_t v = 0;
  for (size_t i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}

uint64_t Fingerprint(int64_t hash) { return static_cast<uint64_t>(hash); }

uint32_t Crc32(const uint8_t* data, size_t size) {
  uLong crc = crc32(0L, Z_NULL, 0);
  // zlib takes uInt lengths: feed large inputs in pieces.
  while (size > 0) {
    const uInt n = static_cast<uInt>(std::min<size_t>(size, std::numeric_limits<uInt>::max()));
    crc = crc32(crc, data, n);
    data += n;
    size -= n;
  }
  return static_cast<uint32_t>(crc);
}

size_t SliceBytes(size_t cloud_bytes, size_t num_chunks) {
  return (cloud_bytes + num_chunks - 1) / num_chunks;
}

void SetWhy(std::string* why, const std::string& text) {
  if (why != nullptr) *why = "object_cloud_chunk_t: " + text;
}

}  // namespace

std::vector<std::vector<uint8_t>> EncodeCloudChunks(const std::vector<uint8_t>& cloud,
                                                    size_t max_slice_bytes) {
  if (max_slice_bytes == 0) throw std::invalid_argument("EncodeCloudChunks: max_slice_bytes is 0");
  if (cloud.size() < kCloudHeadBytes ||
      ReadBigEndian(cloud.data(), 8) != Fingerprint(graspfill::object_cloud_t::getHash())) {
    throw std::invalid_argument("EncodeCloudChunks: the bytes are not an object_cloud_t");
  }
  if (cloud.size() > kMaxChunkedCloudBytes) {
    throw std::invalid_argument("EncodeCloudChunks: a cloud of " + std::to_string(cloud.size()) +
                                " bytes is over " + std::to_string(kMaxChunkedCloudBytes));
  }
  const size_t num_chunks = (cloud.size() + max_slice_bytes - 1) / max_slice_bytes;
  const size_t slice = SliceBytes(cloud.size(), num_chunks);
  graspfill::object_cloud_chunk_t msg{};
  msg.utime = static_cast<int64_t>(ReadBigEndian(cloud.data() + 8, 8));
  msg.seq = static_cast<int64_t>(ReadBigEndian(cloud.data() + 16, 8));
  msg.cloud_num_bytes = static_cast<int32_t>(cloud.size());
  msg.cloud_crc32 = static_cast<int32_t>(Crc32(cloud.data(), cloud.size()));
  msg.num_chunks = static_cast<int32_t>(num_chunks);
  std::vector<std::vector<uint8_t>> out(num_chunks);
  for (size_t i = 0; i < num_chunks; ++i) {
    const size_t offset = i * slice;
    const size_t n = std::min(slice, cloud.size() - offset);
    msg.chunk_index = static_cast<int32_t>(i);
    msg.offset = static_cast<int32_t>(offset);
    msg.num_bytes = static_cast<int32_t>(n);
    msg.data.assign(cloud.begin() + static_cast<std::ptrdiff_t>(offset),
                    cloud.begin() + static_cast<std::ptrdiff_t>(offset + n));
    out[i].resize(static_cast<size_t>(msg.getEncodedSize()));
    if (msg.encode(out[i].data(), 0, static_cast<int>(out[i].size())) != static_cast<int>(out[i].size())) {
      throw std::logic_error("EncodeCloudChunks: lcm encode failed");
    }
  }
  return out;
}

void CloudChunkAssembler::ClearHad() {
  for (uint32_t word : had_words_) had_bits_[word] = 0;
  had_words_.clear();
}

CloudChunkAssembler::Result CloudChunkAssembler::Add(const void* data, size_t size, std::string* why) {
  const auto* bytes = static_cast<const uint8_t*>(data);
  if (bytes == nullptr || size < 8) {
    SetWhy(why, "a message of " + std::to_string(size) + " bytes (malformed)");
    return Result::kMalformed;
  }
  const uint64_t fingerprint = ReadBigEndian(bytes, 8);
  if (fingerprint == Fingerprint(graspfill::object_cloud_t::getHash())) {
    if (pending_) ++dropped_unfinished_;
    pending_ = false;
    cloud_.assign(bytes, bytes + size);  // whole already (a log, memq://): its decoder checks it
    return Result::kComplete;
  }
  if (fingerprint != Fingerprint(graspfill::object_cloud_chunk_t::getHash())) {
    SetWhy(why, "neither object_cloud_t nor object_cloud_chunk_t (wrong type hash; malformed)");
    return Result::kMalformed;
  }
  if (size < kChunkHeaderBytes) {
    SetWhy(why, "truncated header (" + std::to_string(size) + " bytes; malformed)");
    return Result::kMalformed;
  }
  Key key;
  key.utime = static_cast<int64_t>(ReadBigEndian(bytes + 8, 8));
  key.seq = static_cast<int64_t>(ReadBigEndian(bytes + 16, 8));
  const auto field = [bytes](size_t i) {
    return static_cast<int32_t>(static_cast<uint32_t>(ReadBigEndian(bytes + 24 + 4 * i, 4)));
  };
  const int32_t cloud_bytes = field(0);
  key.crc32 = static_cast<uint32_t>(field(1));
  const int32_t num_chunks = field(2), index = field(3), offset = field(4), num_bytes = field(5);
  if (cloud_bytes <= 0 || static_cast<size_t>(cloud_bytes) > kMaxChunkedCloudBytes || num_chunks <= 0 ||
      num_chunks > cloud_bytes) {
    SetWhy(why, "a cloud of " + std::to_string(cloud_bytes) + " bytes in " + std::to_string(num_chunks) +
                    " slices (malformed)");
    return Result::kMalformed;
  }
  key.num_bytes = static_cast<uint32_t>(cloud_bytes);
  key.num_chunks = static_cast<uint32_t>(num_chunks);
  const size_t slice = SliceBytes(key.num_bytes, key.num_chunks);
  const size_t expected_offset = static_cast<size_t>(index) * slice;
  if (index < 0 || index >= num_chunks || offset < 0 || static_cast<size_t>(offset) != expected_offset ||
      expected_offset >= key.num_bytes || num_bytes < 0 ||
      static_cast<size_t>(num_bytes) != std::min(slice, key.num_bytes - expected_offset) ||
      size != kChunkHeaderBytes + static_cast<size_t>(num_bytes)) {
    SetWhy(why, "slice " + std::to_string(index) + " of " + std::to_string(num_chunks) + " at " +
                    std::to_string(offset) + " with " + std::to_string(num_bytes) +
                    " bytes in a message of " + std::to_string(size) + " does not fit a cloud of " +
                    std::to_string(cloud_bytes) + " bytes (malformed)");
    return Result::kMalformed;
  }
  if (completed_ && key == completed_key_) return Result::kRepeat;
  if (!pending_ || !(key == pending_key_)) {
    if (pending_) ++dropped_unfinished_;
    pending_ = true;
    pending_key_ = key;
    ClearHad();
    // Grown, never shrunk or cleared: a header claiming a large cloud costs
    // its allocation once, not a pass over it each time (every byte of the
    // cloud is written by its slices before it completes).
    const size_t words = (key.num_chunks + 63) / 64;
    if (had_bits_.size() < words) had_bits_.resize(words, 0);
    if (joining_.size() < key.num_bytes) joining_.resize(key.num_bytes);
    slices_missing_ = key.num_chunks;
  }
  const size_t word = static_cast<size_t>(index) / 64;
  const uint64_t bit = uint64_t{1} << (static_cast<size_t>(index) % 64);
  if ((had_bits_[word] & bit) != 0) return Result::kRepeat;
  if (had_bits_[word] == 0) had_words_.push_back(static_cast<uint32_t>(word));
  had_bits_[word] |= bit;
  std::memcpy(joining_.data() + expected_offset, bytes + kChunkHeaderBytes, static_cast<size_t>(num_bytes));
  if (--slices_missing_ > 0) return Result::kPending;
  pending_ = false;
  ClearHad();
  if (Crc32(joining_.data(), key.num_bytes) != key.crc32) {
    completed_ = false;
    SetWhy(why, "the joined cloud's CRC-32 differs from its slices' (malformed)");
    return Result::kMalformed;
  }
  // A copy of what the slices brought, so no more than they sent.
  cloud_.assign(joining_.begin(), joining_.begin() + static_cast<std::ptrdiff_t>(key.num_bytes));
  completed_ = true;
  completed_key_ = key;
  return Result::kComplete;
}

}  // namespace graspfill::io
