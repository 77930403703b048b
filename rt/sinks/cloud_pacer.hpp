// SPDX-License-Identifier: BSD-3-Clause
// Sends each model as one-datagram slices (io::EncodeCloudChunks), a few
// milliseconds apart, from a thread of its own: on LCM's UDP multicast a
// subscriber that keeps the kernel's default receive buffer lost whole
// models of two or three datagrams when they came on top of other traffic
// (depth frames), and never lost a paced slice
// (docs/measurements/2026-12-06-cloud-delivery.md). The caller hands over
// the encoded cloud and goes on; nothing here is on the per-frame path.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "graspfill/io/cloud_chunks.hpp"

namespace graspfill::rt {

/// How a model goes out on UDP multicast.
struct CloudPacing {
  /// Bytes of the encoded cloud per message: one UDP datagram each
  /// (io::kCloudSliceBytes).
  size_t slice_bytes{io::kCloudSliceBytes};
  /// Time after each message before the next [ms]: a subscriber's LCM
  /// thread empties its socket between two. With depth frames on the bus
  /// and the CPUs busy, slices 5 or 10 ms apart were never lost where
  /// whole models were (the measurement page); 5 ms delays a model of
  /// three slices by 10 ms.
  double gap_ms{5.0};
  /// How many times each model's slices are sent, one round after the
  /// other (a subscriber joins each model once and ignores repeats): with
  /// 2, a slice lost to a subscriber that was not scheduled in time is
  /// sent again 15 ms or more later.
  int copies{2};
};

/// A thread that sends queued clouds' slices, paced.
///
/// Thread safety: Submit from any thread.
class CloudPacer {
 public:
  /// Sends one message on a channel; true if LCM took it. Called on the
  /// pacer's thread.
  using Send = std::function<bool(const std::string& channel, const std::vector<uint8_t>& bytes)>;

  /// @throws std::invalid_argument on slice_bytes 0, gap_ms < 0 or
  ///   copies < 1.
  CloudPacer(const CloudPacing& pacing, Send send);
  /// Sends what was submitted, then stops (a session's final model goes
  /// out before the program exits).
  ~CloudPacer();
  CloudPacer(const CloudPacer&) = delete;
  CloudPacer& operator=(const CloudPacer&) = delete;

  /// Queues an encoded object_cloud_t (EncodeObjectCloud's bytes) for
  /// `channel`; never waits. When kMaxQueued clouds wait already, the oldest is dropped
  /// (counted): the planner wants the newest.
  void Submit(const std::string& channel, std::vector<uint8_t> encoded_cloud);

  /// Waits until every submitted cloud went out; false after `timeout_ms`.
  bool Flush(int timeout_ms);

  /// Messages LCM did not take; clouds dropped from a full queue.
  int64_t send_failures() const;
  int64_t dropped() const;

  static constexpr size_t kMaxQueued = 8;

 private:
  void Loop();

  struct Queued {
    std::string channel;
    std::vector<uint8_t> cloud;
  };

  const CloudPacing pacing_;
  const Send send_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Queued> queued_;
  bool sending_{false};  // a cloud taken from the queue is going out
  bool stop_{false};
  int64_t send_failures_{0};
  int64_t dropped_{0};
  std::thread thread_;  // last: started once the rest exists
};

}  // namespace graspfill::rt
