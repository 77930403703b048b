// SPDX-License-Identifier: BSD-3-Clause
// What every input of the module hands to the runtime: depth frames and
// gripper states (and, from recordings, the session description), one event
// at a time, from a live device or a recording.
#pragma once

#include <string>

#include "graspfill/io/messages.hpp"
#include "graspfill/types.hpp"

namespace graspfill::rt {

/// Outcome of asking a source for its next event.
enum class FrameResult {
  kOk,           ///< an event was produced
  kBadFrame,     ///< this event was unusable (reason in the error text);
                 ///< the source can go on
  kEndOfStream,  ///< no more events; every later call returns this again
};

/// One event from a source. Only the member named by `kind` is meaningful;
/// the others keep whatever they held, so that a caller reusing one
/// SourceEvent keeps the buffers' capacity (no per-frame allocation).
struct SourceEvent {
  /// kSession comes only from sources asked for it (see
  /// LcmLogSource::Config::session_events), so callers that know depth and
  /// gripper states only never see it.
  enum class Kind { kDepth, kGripperState, kSession };
  Kind kind{Kind::kDepth};
  DepthFrame depth;                ///< valid when kind == kDepth and the result is kOk
  GripperState gripper;            ///< valid when kind == kGripperState and kOk
  io::SessionDescription session;  ///< valid when kind == kSession and kOk
  std::string error;               ///< why, when the result is kBadFrame
};

/// A source of events (OpenNI2 device or .oni file, LCM log, ...).
/// Implementations are not thread safe: one thread (the source's reader
/// thread in rt/) calls Next() in a loop.
class FrameSource {
 public:
  virtual ~FrameSource() = default;

  /// Produces the next event into *event (reusing its buffers). Blocks at
  /// most as long as the implementation documents.
  virtual FrameResult Next(SourceEvent* event) = 0;
};

}  // namespace graspfill::rt
