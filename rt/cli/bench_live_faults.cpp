// SPDX-License-Identifier: BSD-3-Clause
#include "bench_live_faults.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "claw_option.hpp"

namespace graspfill::cli {
namespace {

// Byte offsets in LCM's big-endian encoding (after the 8-byte fingerprint),
// from lcmtypes/depth_image_t.lcm and gripper_state_t.lcm.
constexpr size_t kUtimeAt = 8;
constexpr size_t kDepthWidthAt = 16, kDepthFxAt = 24, kDepthScaleAt = 56, kDepthEncodingAt = 64,
                 kDepthDataAt = 69;
constexpr size_t kGripperFrameAt = 16, kGripperPositionAt = 17, kGripperOrientationAt = 41;

void PutBigEndian(std::vector<uint8_t>* m, size_t at, uint64_t value, int bytes) {
  if (at + bytes > m->size()) throw std::runtime_error("a sample message is too short to break");
  for (int i = 0; i < bytes; ++i) (*m)[at + i] = static_cast<uint8_t>(value >> (8 * (bytes - 1 - i)));
}

void PutDouble(std::vector<uint8_t>* m, size_t at, double value) {
  uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof(bits));
  PutBigEndian(m, at, bits, 8);
}

std::vector<uint8_t> Truncated(const std::vector<uint8_t>& m) {
  return {m.begin(), m.begin() + static_cast<std::ptrdiff_t>(m.size() / 2)};
}

std::vector<uint8_t> Patched(std::vector<uint8_t> m, size_t at, uint64_t value, int bytes) {
  PutBigEndian(&m, at, value, bytes);
  return m;
}

std::vector<uint8_t> PatchedDouble(std::vector<uint8_t> m, size_t at, double value) {
  PutDouble(&m, at, value);
  return m;
}

// What the live module counts a message on `channel` as: the decoder's
// reason, or for a session that decodes, out_of_limits beyond the limits.
io::MessageError RejectReason(const io::ChannelNames& channels, const std::string& channel,
                              const std::vector<uint8_t>& m) {
  std::string error;
  io::MessageError reason = io::MessageError::kNone;
  if (channel == channels.depth) {
    DepthFrame frame;
    io::DecodeDepthImage(m.data(), m.size(), &frame, &error, &reason);
  } else if (channel == channels.gripper_state) {
    GripperState state;
    io::DecodeGripperState(m.data(), m.size(), Eigen::Isometry3d::Identity(), &state, &error, &reason);
  } else {
    io::SessionDescription session;
    if (io::DecodeSessionDescription(m.data(), m.size(), &session, &error, &reason) &&
        !io::SessionWithinLimits(session, &error)) {
      reason = io::MessageError::kOutOfLimits;
    }
  }
  return reason;
}

}  // namespace

void ShiftEncodedUtime(std::vector<uint8_t>* message, int64_t offset_us) {
  if (message->size() < kUtimeAt + 8) return;  // no utime to shift: the decoder rejects it
  uint64_t utime = 0;
  for (int i = 0; i < 8; ++i) utime = (utime << 8) | (*message)[kUtimeAt + i];
  PutBigEndian(message, kUtimeAt, utime + static_cast<uint64_t>(offset_us), 8);
}

MalformedMessages::MalformedMessages(const io::ChannelNames& channels, const std::vector<uint8_t>& depth,
                                     const std::vector<uint8_t>& gripper_state) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  io::SessionDescription session;
  DescribeBuiltinClaw("three-finger", claw::ProceduralClawConfig{}, &session);
  const std::vector<uint8_t> session_bytes = io::EncodeSessionDescription(session);
  // A traversal name of the built-in name's length, written over it (the
  // encoder refuses to write one).
  std::vector<uint8_t> traversal = session_bytes;
  const std::string name = "three-finger", evil = "../../victim";
  const auto at = std::search(traversal.begin(), traversal.end(), name.begin(), name.end());
  if (at == traversal.end()) throw std::runtime_error("the claw name is not in its description");
  std::copy(evil.begin(), evil.end(), at);
  io::SessionDescription big_voxel = session, far_workspace = session, far_camera = session;
  big_voxel.voxel_m = 1.0;
  far_workspace.workspace_G =
      Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-1e300), Eigen::Vector3d::Constant(1e300));
  far_camera.T_C_B.translation() = Eigen::Vector3d(100.0, 0.0, 0.0);

  const auto add = [&](const std::string& channel, std::vector<uint8_t> m, const std::string& defect) {
    const io::MessageError reason = RejectReason(channels, channel, m);
    if (reason == io::MessageError::kNone) {
      throw std::runtime_error("the malformed message '" + defect + "' decodes");
    }
    messages_.push_back({channel, std::move(m), defect, reason});
  };
  std::vector<uint8_t> bad_fingerprint = depth;
  bad_fingerprint[0] ^= 0x5a;
  add(channels.depth, Truncated(depth), "depth: truncated");
  add(channels.depth, bad_fingerprint, "depth: another type's fingerprint");
  add(channels.depth, gripper_state, "depth: a gripper state on the depth channel");
  add(channels.depth, Patched(depth, kDepthWidthAt, 1u << 20, 4), "depth: width 2^20");
  add(channels.depth, PatchedDouble(depth, kDepthFxAt, nan), "depth: fx NaN");
  add(channels.depth, PatchedDouble(depth, kDepthScaleAt, -1.0), "depth: depth scale -1");
  add(channels.depth, Patched(depth, kDepthEncodingAt, 7, 1), "depth: encoding 7");
  add(channels.depth, Patched(depth, kDepthDataAt, 0xffff, 2), "depth: pixel data's first bytes");
  add(channels.gripper_state, Truncated(gripper_state), "gripper state: truncated");
  add(channels.gripper_state, depth, "gripper state: a depth image on its channel");
  add(channels.gripper_state, PatchedDouble(gripper_state, kGripperPositionAt, nan),
      "gripper state: position NaN");
  std::vector<uint8_t> unnormalized = gripper_state;
  for (int i = 0; i < 4; ++i) PutDouble(&unnormalized, kGripperOrientationAt + 8 * i, 2.0);
  add(channels.gripper_state, unnormalized, "gripper state: quaternion of norm 4");
  add(channels.gripper_state, Patched(gripper_state, kGripperFrameAt, 9, 1), "gripper state: frame 9");
  add(channels.gripper_state, Patched(gripper_state, kUtimeAt, static_cast<uint64_t>(-5), 8),
      "gripper state: utime -5");
  add(channels.session, Truncated(session_bytes), "session: truncated");
  add(channels.session, traversal, "session: claw name ../../victim");
  add(channels.session, io::EncodeSessionDescription(big_voxel), "session: voxel 1 m");
  add(channels.session, io::EncodeSessionDescription(far_workspace), "session: workspace +-1e300 m");
  add(channels.session, io::EncodeSessionDescription(far_camera), "session: hand-eye 100 m away");
}

}  // namespace graspfill::cli
