// SPDX-License-Identifier: BSD-3-Clause
// What every message codec in src/io shares (private to graspfill_io). Two
// rules shape the codecs:
//  - Bytes from the bus are untrusted. The lcm-gen decoders resize their
//    vectors to the count read from the wire *before* checking that the
//    bytes are there (a negative or huge count throws or allocates
//    gigabytes), so every message is first walked with WireReader, which
//    checks each count against the bytes left, and only then decoded.
//  - Depth images arrive at 30 Hz: they are parsed in place (no copy of the
//    payload) and inflated with a per-thread zlib stream into per-thread
//    scratch, so the steady state allocates nothing (depth_image_codec.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "graspfill/io/messages.hpp"

namespace graspfill::io::wire {

// Why the decode in progress on this thread failed; WithReason reads it.
MessageError& FailureReason();

void SetError(std::string* error, const std::string& message, MessageError reason = MessageError::kMalformed);

std::string FormatLimit(double v);

// `text` fit for a one-line message: bytes outside printable ASCII as \xHH,
// at most `max_chars` of it.
std::string Printable(const std::string& text, size_t max_chars);

bool UtimeInRange(const char* type, int64_t utime, std::string* error);

// Reads LCM's wire format (big-endian, counts before arrays) with bounds
// checks. Every accessor returns false instead of reading past the end.
class WireReader {
 public:
  WireReader(const void* data, size_t size) : data_(static_cast<const uint8_t*>(data)), size_(size) {}

  size_t remaining() const { return size_ - pos_; }

  bool Skip(size_t n) {
    if (n > remaining()) return false;
    pos_ += n;
    return true;
  }
  bool Bytes(size_t n, const uint8_t** p) {
    if (n > remaining()) return false;
    *p = data_ + pos_;
    pos_ += n;
    return true;
  }
  bool I8(int8_t* v) {
    uint64_t u;
    if (!BigEndian(1, &u)) return false;
    *v = static_cast<int8_t>(u);
    return true;
  }
  bool I32(int32_t* v) {
    uint64_t u;
    if (!BigEndian(4, &u)) return false;
    *v = static_cast<int32_t>(static_cast<uint32_t>(u));
    return true;
  }
  bool I64(int64_t* v) {
    uint64_t u;
    if (!BigEndian(8, &u)) return false;
    *v = static_cast<int64_t>(u);
    return true;
  }
  bool F64(double* v) {
    uint64_t u;
    if (!BigEndian(8, &u)) return false;
    std::memcpy(v, &u, sizeof(*v));
    return true;
  }
  // An array count followed by `count` elements of `element_bytes` each:
  // the count must be >= 0 and the elements must fit in what is left.
  bool Count(int32_t* count, size_t element_bytes) { return I32(count) && CountFits(*count, element_bytes); }
  bool CountFits(int32_t count, size_t element_bytes) const {
    return count >= 0 && static_cast<size_t>(count) <= remaining() / (element_bytes ? element_bytes : 1);
  }
  // An LCM string: int32 length including the NUL, then the bytes. The
  // NUL must end it and be its only one: lcm-gen decodes embedded NULs
  // into std::string but encodes with strlen, so such a string would
  // decode and then fail to re-encode (found by fuzz_object_cloud).
  bool SkipString() {
    int32_t length;
    const uint8_t* bytes = nullptr;
    if (!I32(&length) || length < 1 || !Bytes(static_cast<size_t>(length), &bytes)) return false;
    return std::memchr(bytes, 0, static_cast<size_t>(length)) == bytes + length - 1;
  }
  bool Hash(int64_t expected) {
    int64_t hash;
    return I64(&hash) && hash == expected;
  }

 private:
  bool BigEndian(size_t n, uint64_t* v) {
    if (n > remaining()) return false;
    uint64_t u = 0;
    for (size_t i = 0; i < n; ++i) u = (u << 8) | data_[pos_ + i];
    pos_ += n;
    *v = u;
    return true;
  }

  const uint8_t* data_;
  size_t size_;
  size_t pos_{0};
};

bool AllFinite(const double* v, int n);

// Builds an isometry from position + (w, x, y, z) after checking both.
bool PoseFromWire(const char* type, const double position[3], const double orientation[4],
                  Eigen::Isometry3d* T, std::string* error);

void PoseToWire(const Eigen::Isometry3d& T, double position[3], double orientation[4]);

template <typename Message>
std::vector<uint8_t> EncodeMessage(const Message& msg) {
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  const int n = msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  if (n != static_cast<int>(bytes.size())) {
    throw std::logic_error(std::string("lcm encode failed for ") + Message::getTypeName());
  }
  return bytes;
}

// Runs the lcm-gen decoder on bytes that a walker has already validated.
// The try/catch is a second line of defence (bad_alloc) since handlers on
// the bus must not throw.
template <typename Message>
bool DecodeMessage(const void* data, size_t size, Message* msg, std::string* error) {
  try {
    const int n = msg->decode(data, 0, static_cast<int>(size));
    if (n != static_cast<int>(size)) {
      SetError(error, std::string(Message::getTypeName()) + ": lcm decode failed");
      return false;
    }
  } catch (const std::exception& e) {
    SetError(error, std::string(Message::getTypeName()) + ": lcm decode failed: " + e.what());
    return false;
  }
  return true;
}

// Common checks before any walk: a null pointer or a message bigger than
// lcm's int-sized decoders can address.
bool CheckBuffer(const void* data, size_t size, const void* out, const char* type, std::string* error);

// Runs `decode` and reports why it failed in `reason` (when not null).
template <typename F>
bool WithReason(MessageError* reason, F decode) {
  FailureReason() = MessageError::kNone;
  const bool ok = decode();
  if (reason != nullptr) {
    *reason = ok ? MessageError::kNone
                 : (FailureReason() == MessageError::kNone ? MessageError::kMalformed : FailureReason());
  }
  return ok;
}

}  // namespace graspfill::io::wire
