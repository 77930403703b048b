// SPDX-License-Identifier: BSD-3-Clause
// object_cloud_t from a live LCM bus through liblcm's C API, for the Python
// module's Subscriber (Debian ships no Python LCM binding). Plain C++: the
// binding (subscriber_binding.cpp) releases the GIL around Wait().
#pragma once

#include <lcm/lcm.h>

#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

#include "graspfill/io/cloud_chunks.hpp"
#include "graspfill/types.hpp"

namespace graspfill::python {

/// Subscribes to one channel, joins the slices a udpm publisher cuts each
/// cloud into (io::CloudChunkAssembler; a log's whole object_cloud_t passes
/// through) and decodes the clouds with graspfill's own decoder
/// (io::DecodeObjectCloud).
///
/// Thread safety: any thread may call any method; one Wait() runs at a time
/// (the others, and Close(), wait for it: keep Wait()'s timeout short).
class CloudSubscriber {
 public:
  /// @param url  an LCM URL; "" = LCM's default (LCM_DEFAULT_URL, else its
  ///   UDP multicast).
  /// @param channel  the channel (LCM matches it as a regular expression).
  /// @throws std::runtime_error naming the URL if LCM cannot be set up.
  CloudSubscriber(const std::string& url, const std::string& channel);
  ~CloudSubscriber();
  CloudSubscriber(const CloudSubscriber&) = delete;
  CloudSubscriber& operator=(const CloudSubscriber&) = delete;

  enum class WaitResult {
    kCloud,       ///< *cloud holds the next message
    kTimeout,     ///< no whole cloud arrived in time (maybe some of its slices)
    kBadMessage,  ///< a message did not decode: dropped, counted, *error says why
    kEnded,       ///< LCM ended: a file:// log's end, or the bus failed (for good)
  };
  /// Takes the next message, waiting up to `timeout_ms` (>= 0) for one.
  /// @throws std::runtime_error after Close().
  WaitResult Wait(int timeout_ms, ObjectCloud* cloud, std::string* error);

  /// Unsubscribes and closes the LCM instance; later Wait()s throw.
  void Close();
  bool closed() const;
  /// Messages that did not decode, since construction.
  int64_t bad_messages() const;

 private:
  // LCM's C handler: copies the payload, never throws (a C callback).
  static void OnMessage(const lcm_recv_buf_t* buffer, const char* channel, void* self);
  WaitResult DecodeNext(ObjectCloud* cloud, std::string* error);

  mutable std::mutex mutex_;
  lcm_t* lcm_{nullptr};
  lcm_subscription_t* subscription_{nullptr};
  // Payloads handled but not yet taken (one lcm_handle may dispatch several).
  std::deque<std::vector<uint8_t>> received_;
  io::CloudChunkAssembler slices_;
  bool dropped_for_memory_{false};
  bool ended_{false};
  int64_t bad_messages_{0};
};

}  // namespace graspfill::python
