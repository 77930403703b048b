// SPDX-License-Identifier: BSD-3-Clause
// The depth frames of a graspfill recording (an LCM log of depth_image_t),
// as the replay driver serves them: indexed once when the device is
// opened (count, size, intrinsics, rate), then read and decoded one frame
// at a time, in file order, from a reader of their own.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/types.hpp"

namespace graspfill::openni2_replay {

/// What indexing a recording found (no pixel is decoded but the first
/// frame's).
struct RecordingIndex {
  std::string path;
  std::string depth_channel;
  CameraIntrinsics intrinsics;  ///< of the first depth image
  double depth_scale_m{0.001};  ///< meters per unit, as recorded
  int num_frames{0};
  int64_t first_utime{0};
  /// Recorded rate, rounded [frames/s]: the median time between frames
  /// (30 for a single frame).
  int fps{30};
};

/// Indexes `path`'s depth images on `depth_channel`.
/// @throws std::runtime_error naming the file when it cannot be read, is
///   not an LCM log, has no depth image on the channel, or its first depth
///   image does not decode.
RecordingIndex IndexRecording(const std::string& path, const std::string& depth_channel);

/// Reads the depth frames of an indexed recording from its start.
class RecordingReader {
 public:
  explicit RecordingReader(const RecordingIndex& index);
  /// Decodes the next depth image of the recording's channel into *frame
  /// (meters, reusing its buffer). Returns false at the end; a depth image
  /// that does not decode, or is not the first one's size, is skipped and
  /// counted in skipped().
  bool Next(DepthFrame* frame);
  int skipped() const { return skipped_; }

 private:
  const RecordingIndex index_;
  io::LcmLogReader reader_;
  io::LogEvent event_;
  std::string error_;
  int skipped_{0};
};

}  // namespace graspfill::openni2_replay
