// SPDX-License-Identifier: BSD-3-Clause
#include "module/session_loop.hpp"

#include <thread>
#include <utility>

namespace graspfill::rt {

SessionLoop::SessionLoop(SessionLoopLimits limits) : limits_(std::move(limits)), start_(Clock::now()) {}

void SessionLoop::NoteDepthFrame() { last_depth_ns_ = Clock::now().time_since_epoch().count(); }

LoopEnd SessionLoop::Limit(Clock::time_point now) const {
  if (limits_.interrupted != nullptr && limits_.interrupted->load()) return LoopEnd::kInterrupted;
  if (limits_.duration_s > 0 && std::chrono::duration<double>(now - start_).count() > limits_.duration_s) {
    return LoopEnd::kDuration;
  }
  const int64_t last_ns = last_depth_ns_;
  if (limits_.idle_exit_s > 0 && last_ns != 0 &&
      (now.time_since_epoch().count() - last_ns) * 1e-9 > limits_.idle_exit_s) {
    return LoopEnd::kIdle;
  }
  return LoopEnd::kEndOfStream;  // none
}

LoopEnd SessionLoop::Run(FrameSource* source, EventSink* sink) {
  start_ = Clock::now();
  Clock::time_point last_tick = start_;
  SourceEvent event;  // reused: its buffers keep their capacity
  for (;;) {
    const Clock::time_point now = Clock::now();
    const LoopEnd limit = Limit(now);
    if (limit != LoopEnd::kEndOfStream) return limit;
    if (limits_.on_tick && now - last_tick >= std::chrono::milliseconds(limits_.tick_ms)) {
      limits_.on_tick();
      last_tick = now;
    }
    if (source == nullptr) {
      std::this_thread::sleep_for(std::chrono::milliseconds(limits_.poll_ms));
      continue;
    }
    const FrameResult result = source->Next(&event);
    if (result == FrameResult::kEndOfStream) return LoopEnd::kEndOfStream;
    if (result == FrameResult::kOk && event.kind == SourceEvent::Kind::kDepth) NoteDepthFrame();
    const bool go_on = result == FrameResult::kOk ? sink->OnEvent(event) : sink->OnBadEvent(event);
    if (!go_on) return LoopEnd::kSinkStopped;
  }
}

}  // namespace graspfill::rt
