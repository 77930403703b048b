// SPDX-License-Identifier: BSD-3-Clause
// Live input from the LCM bus: gripper states from the robot (and, where a
// camera driver publishes them, depth images), decoded on a receive thread
// and handed to callbacks (typically GraspModule::Push*). Session
// descriptions on the bus set the hand-eye calibration and the intrinsics
// override for what follows them, and go to their own callback; one that
// does not decode (a claw name that is not a plain name included) or asks
// for values beyond io::SessionWithinLimits is rejected whole: counted,
// handed to the reject callback, and nothing of it applies.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "graspfill/io/messages.hpp"
#include "sources/session_overrides.hpp"

namespace graspfill::rt {

using io::BadMessageCounts;

class LcmBusSubscriber {
 public:
  struct Config {
    /// LCM URL; "" = LCM's default (LCM_DEFAULT_URL, else udpm).
    std::string url;
    io::ChannelNames channels;
    /// Hand-eye, intrinsics and clock offset over the session descriptions'
    /// (a depth image of another size than the intrinsics is counted as a
    /// decode error).
    SourceOverrides overrides;
    /// Depth images with more pixels are counted as kBadSize and dropped,
    /// before their decoded size is allocated (io::DecodeDepthImage).
    int64_t max_depth_pixels{io::kDefaultMaxDepthPixels};
  };
  using StateCallback = std::function<void(const GripperState&)>;
  using DepthCallback = std::function<void(const DepthFrame&)>;
  using SessionCallback = std::function<void(const io::SessionDescription&)>;
  /// A rejected session description: the reason and a one-line why.
  using RejectCallback = std::function<void(io::MessageError, const std::string&)>;

  /// Subscribes and starts the receive thread. `on_depth` may be empty (no
  /// depth subscription), and so may `on_session` (session descriptions are
  /// still applied, see Config) and `on_session_rejected`. Callbacks run on
  /// the receive thread and must not throw. Throws std::runtime_error if
  /// LCM cannot start on `url`.
  LcmBusSubscriber(const Config& config, StateCallback on_state, DepthCallback on_depth = {},
                   SessionCallback on_session = {}, RejectCallback on_session_rejected = {});
  /// Stops and joins the receive thread.
  ~LcmBusSubscriber();
  LcmBusSubscriber(const LcmBusSubscriber&) = delete;
  LcmBusSubscriber& operator=(const LcmBusSubscriber&) = delete;

  int64_t states_received() const { return states_received_; }
  int64_t depth_received() const { return depth_received_; }
  int64_t sessions_received() const { return sessions_received_; }
  /// Messages on our channels that did not decode or were dropped
  /// (counted, never thrown): bad_messages().total().
  int64_t decode_errors() const { return decode_errors_; }
  /// The same, per reason (a snapshot; safe from any thread). Besides the
  /// decoders' reasons (io::MessageError): kIntrinsicsMismatch, a depth
  /// image of another size than the session's intrinsics override, and
  /// kNonMonotonicTime, a gripper state not newer than the last one taken
  /// or a depth image older than the last one (after
  /// kResyncAfterNonMonotonic such messages in a row on one channel the
  /// next is taken as a new time base: a restarted publisher, or one bogus
  /// stamp far in the future, must not silence the channel).
  BadMessageCounts bad_messages() const;
  static constexpr int kResyncAfterNonMonotonic = 10;

  /// What the receive thread does with a message on our channels, callable
  /// without a socket (a test or a fuzzer feeds bytes as the bus would). One
  /// thread at a time: not while messages also come on the bus. HandleDepth
  /// drops the message uncounted when constructed without `on_depth`, as
  /// the bus does (no subscription).
  void HandleGripperState(const void* data, size_t size);
  void HandleDepth(const void* data, size_t size);
  void HandleSession(const void* data, size_t size);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::atomic<int64_t> states_received_{0};
  std::atomic<int64_t> depth_received_{0};
  std::atomic<int64_t> sessions_received_{0};
  std::atomic<int64_t> decode_errors_{0};
  std::array<std::atomic<int64_t>, BadMessageCounts::kNumReasons> bad_by_reason_{};
  void CountBad(io::MessageError reason);
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace graspfill::rt
