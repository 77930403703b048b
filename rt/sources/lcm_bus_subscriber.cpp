// SPDX-License-Identifier: BSD-3-Clause
#include "sources/lcm_bus_subscriber.hpp"

#include <lcm/lcm-cpp.hpp>

#include "sources/session_overrides.hpp"

#include <stdexcept>
#include <utility>

namespace graspfill::rt {

struct LcmBusSubscriber::Impl {
  explicit Impl(const std::string& url) : lcm(url) {}
  lcm::LCM lcm;
  Config config;
  StateCallback on_state;
  DepthCallback on_depth;
  SessionCallback on_session;
  RejectCallback on_session_rejected;
  GripperState state;  // decode targets, reused
  DepthFrame depth;
  io::SessionDescription session;
  // What the last session description set (receive thread only).
  Eigen::Isometry3d T_C_B{Eigen::Isometry3d::Identity()};
  std::optional<CameraIntrinsics> intrinsics;
  std::string error;
  io::MessageError reason{io::MessageError::kNone};
  // Time base per channel (receive thread only), see kNonMonotonicTime.
  struct Clock {
    int64_t last_utime{-1};
    int rejected_in_a_row{0};
  };
  Clock state_clock, depth_clock;
};

namespace {
// Gripper states LCM may queue for this subscriber (see the constructor).
constexpr int kStateQueueCapacity = 2048;

// True if `utime` may follow what `clock` took last (strictly newer when
// `strict`); updates the clock.
template <typename ClockT>
bool TakeTime(ClockT* clock, int64_t utime, bool strict, int resync_after) {
  const bool in_order =
      clock->last_utime < 0 || (strict ? utime > clock->last_utime : utime >= clock->last_utime);
  if (!in_order && ++clock->rejected_in_a_row <= resync_after) return false;
  clock->last_utime = utime;
  clock->rejected_in_a_row = 0;
  return true;
}
}  // namespace

void LcmBusSubscriber::CountBad(io::MessageError reason) {
  ++decode_errors_;
  ++bad_by_reason_[static_cast<size_t>(reason)];
}

BadMessageCounts LcmBusSubscriber::bad_messages() const {
  BadMessageCounts counts;
  for (size_t i = 0; i < counts.by_reason.size(); ++i) counts.by_reason[i] = bad_by_reason_[i];
  return counts;
}

void LcmBusSubscriber::HandleGripperState(const void* data, size_t size) {
  Impl& s = *impl_;
  if (!io::DecodeGripperState(data, size, s.T_C_B, &s.state, &s.error, &s.reason)) {
    CountBad(s.reason);
    return;
  }
  s.state.utime += s.config.overrides.gripper_clock_offset_us;
  if (!TakeTime(&s.state_clock, s.state.utime, true, kResyncAfterNonMonotonic)) {
    CountBad(io::MessageError::kNonMonotonicTime);
    return;
  }
  ++states_received_;
  if (s.on_state) s.on_state(s.state);
}

void LcmBusSubscriber::HandleDepth(const void* data, size_t size) {
  Impl& s = *impl_;
  if (!s.on_depth) return;  // not subscribed
  if (!io::DecodeDepthImage(data, size, &s.depth, &s.error, &s.reason, s.config.max_depth_pixels)) {
    CountBad(s.reason);
    return;
  }
  if (!ApplyIntrinsicsOverride(s.intrinsics, &s.depth, &s.error)) {
    CountBad(io::MessageError::kIntrinsicsMismatch);
    return;
  }
  if (!TakeTime(&s.depth_clock, s.depth.utime, false, kResyncAfterNonMonotonic)) {
    CountBad(io::MessageError::kNonMonotonicTime);
    return;
  }
  ++depth_received_;
  s.on_depth(s.depth);
}

void LcmBusSubscriber::HandleSession(const void* data, size_t size) {
  Impl& s = *impl_;
  const auto reject = [&](io::MessageError reason, const std::string& why) {
    CountBad(reason);
    if (s.on_session_rejected) s.on_session_rejected(reason, why);
  };
  if (!io::DecodeSessionDescription(data, size, &s.session, &s.error, &s.reason)) {
    reject(s.reason, s.error);
    return;
  }
  if (!io::SessionWithinLimits(s.session, &s.error)) {
    reject(io::MessageError::kOutOfLimits, "session_description_t " + s.error);
    return;
  }
  ++sessions_received_;
  if (s.config.overrides.T_C_B_from_session) s.T_C_B = s.session.T_C_B;
  if (s.config.overrides.intrinsics_from_session) s.intrinsics = s.session.intrinsics;
  if (s.on_session) s.on_session(s.session);
}

LcmBusSubscriber::LcmBusSubscriber(const Config& config, StateCallback on_state, DepthCallback on_depth,
                                   SessionCallback on_session, RejectCallback on_session_rejected)
    : impl_(std::make_unique<Impl>(config.url)) {
  if (!impl_->lcm.good()) {
    throw std::runtime_error("cannot start LCM on '" +
                             (config.url.empty() ? std::string("LCM's default URL") : config.url) + "'");
  }
  impl_->config = config;
  impl_->on_state = std::move(on_state);
  impl_->on_depth = std::move(on_depth);
  impl_->on_session = std::move(on_session);
  impl_->on_session_rejected = std::move(on_session_rejected);
  impl_->T_C_B = config.overrides.T_C_B;
  impl_->intrinsics = config.overrides.intrinsics;
  // Handlers are called from LCM's C code: they count errors, never throw.
  lcm::Subscription* states = impl_->lcm.subscribeFunction(
      config.channels.gripper_state,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, LcmBusSubscriber* self) {
        self->HandleGripperState(rbuf->data, rbuf->data_size);
      },
      this);
  // LCM drops what a subscription has queued beyond 30 messages, silently:
  // 75 ms of states at 4x a 100 Hz arm, which one slow depth frame on this
  // thread (decoding it) can outlast, and a frame without the states around
  // it is lost. States are ~100 bytes: 2,048 hold 5 s at 4x for 200 kB.
  states->setQueueCapacity(kStateQueueCapacity);
  if (impl_->on_depth) {
    impl_->lcm.subscribeFunction(
        config.channels.depth,
        +[](const lcm::ReceiveBuffer* rbuf, const std::string&, LcmBusSubscriber* self) {
          self->HandleDepth(rbuf->data, rbuf->data_size);
        },
        this);
  }
  impl_->lcm.subscribeFunction(
      config.channels.session,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, LcmBusSubscriber* self) {
        self->HandleSession(rbuf->data, rbuf->data_size);
      },
      this);
  thread_ = std::thread([this] {
    // Bounded waits so that the destructor is noticed promptly.
    while (!stop_) impl_->lcm.handleTimeout(50);
  });
}

LcmBusSubscriber::~LcmBusSubscriber() {
  stop_ = true;
  thread_.join();
}

}  // namespace graspfill::rt
