// SPDX-License-Identifier: BSD-3-Clause
#include "replay_recording.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "graspfill/io/messages.hpp"

namespace graspfill::openni2_replay {
namespace {

// depth_image_t on the wire: 8-byte type hash, then int64 utime (big-endian).
bool PeekUtime(const std::vector<uint8_t>& data, int64_t* utime) {
  if (data.size() < 16) return false;
  uint64_t v = 0;
  for (int i = 8; i < 16; ++i) v = (v << 8) | data[i];
  *utime = static_cast<int64_t>(v);
  return true;
}

// depth_scale follows utime, width, height and fx, fy, cx, cy.
double PeekDepthScale(const std::vector<uint8_t>& data) {
  constexpr size_t kOffset = 8 + 8 + 4 + 4 + 4 * 8;
  if (data.size() < kOffset + 8) return 0.0;
  uint64_t bits = 0;
  for (size_t i = kOffset; i < kOffset + 8; ++i) bits = (bits << 8) | data[i];
  double scale;
  static_assert(sizeof(scale) == sizeof(bits));
  std::copy_n(reinterpret_cast<const uint8_t*>(&bits), sizeof(bits), reinterpret_cast<uint8_t*>(&scale));
  return scale;
}

}  // namespace

RecordingIndex IndexRecording(const std::string& path, const std::string& depth_channel) {
  RecordingIndex index;
  index.path = path;
  index.depth_channel = depth_channel;
  io::LcmLogReader reader(path);  // throws "cannot open log '<path>': ..."
  io::LogEvent event;
  std::vector<int64_t> utimes;
  io::LogReadResult result;
  while ((result = reader.Next(&event)) == io::LogReadResult::kEvent) {
    if (event.channel != depth_channel) continue;
    int64_t utime = 0;
    if (!PeekUtime(event.data, &utime)) continue;
    if (utimes.empty()) {
      DepthFrame first;
      std::string error;
      if (!io::DecodeDepthImage(event.data.data(), event.data.size(), &first, &error)) {
        throw std::runtime_error("'" + path + "': its first depth image does not decode: " + error);
      }
      index.intrinsics = first.intrinsics;
      index.depth_scale_m = PeekDepthScale(event.data);
      index.first_utime = utime;
    }
    utimes.push_back(utime);
  }
  if (utimes.empty()) {
    throw std::runtime_error("'" + path + "' has no depth image on " + depth_channel +
                             (result == io::LogReadResult::kEnd ? "" : " (" + reader.error() + ")"));
  }
  index.num_frames = static_cast<int>(utimes.size());
  if (utimes.size() > 1) {
    std::vector<int64_t> steps;
    for (size_t i = 1; i < utimes.size(); ++i) steps.push_back(utimes[i] - utimes[i - 1]);
    std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
    const int64_t median_us = steps[steps.size() / 2];
    if (median_us > 0) index.fps = std::max(1, static_cast<int>(std::lround(1e6 / median_us)));
  }
  return index;
}

RecordingReader::RecordingReader(const RecordingIndex& index) : index_(index), reader_(index.path) {}

bool RecordingReader::Next(DepthFrame* frame) {
  while (reader_.Next(&event_) == io::LogReadResult::kEvent) {
    if (event_.channel != index_.depth_channel) continue;
    if (!io::DecodeDepthImage(event_.data.data(), event_.data.size(), frame, &error_) ||
        frame->intrinsics.width != index_.intrinsics.width ||
        frame->intrinsics.height != index_.intrinsics.height) {
      ++skipped_;
      continue;
    }
    return true;
  }
  return false;
}

}  // namespace graspfill::openni2_replay
