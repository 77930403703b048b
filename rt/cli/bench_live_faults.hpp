// SPDX-License-Identifier: BSD-3-Clause
// Malformed messages of every kind the live module subscribes to (depth
// images, gripper states, session descriptions), for `bench live`'s fault
// soak (issue 36): each made from a valid message of the recording by one
// defect a broken or hostile publisher could send, and decoded here first,
// so that the reason the module must count it under is known.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "graspfill/io/messages.hpp"

namespace graspfill::cli {

struct MalformedMessage {
  std::string channel;
  std::vector<uint8_t> data;
  std::string defect;       // what was broken, e.g. "depth: fx NaN"
  io::MessageError reason;  // what the module must count it as
};

/// A fixed cycle of malformed messages, every defect once per cycle.
class MalformedMessages {
 public:
  /// `depth` and `gripper_state`: one valid encoded message of each, from
  /// the recording. @throws std::runtime_error if a defect would decode
  /// (then the soak could not tell a lost reject from an accepted one).
  MalformedMessages(const io::ChannelNames& channels, const std::vector<uint8_t>& depth,
                    const std::vector<uint8_t>& gripper_state);

  /// The next message of the cycle.
  const MalformedMessage& Next() { return messages_[next_++ % messages_.size()]; }
  const std::vector<MalformedMessage>& all() const { return messages_; }

 private:
  std::vector<MalformedMessage> messages_;
  size_t next_{0};
};

/// Adds `offset_us` to the utime (the first field of depth_image_t and
/// gripper_state_t, after LCM's 8-byte fingerprint) of an encoded message,
/// in place: a recording played in a loop without re-encoding its frames.
void ShiftEncodedUtime(std::vector<uint8_t>* message, int64_t offset_us);

}  // namespace graspfill::cli
