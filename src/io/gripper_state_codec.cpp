// SPDX-License-Identifier: BSD-3-Clause
// gripper_state_t (and its v1 layout) <-> GripperState.
#include "graspfill/io/messages.hpp"

#include "wire.hpp"

#include <graspfill/gripper_state_t.hpp>
#include <graspfill/gripper_state_v1_t.hpp>

namespace graspfill::io {
using namespace wire;

std::vector<uint8_t> EncodeGripperState(const GripperState& state) {
  graspfill::gripper_state_t msg{};
  msg.utime = state.utime;
  msg.frame = graspfill::gripper_state_t::FRAME_CAMERA;
  PoseToWire(state.T_C_G, msg.position, msg.orientation);
  msg.opening_m = state.opening_m;
  msg.num_joints = static_cast<int32_t>(state.joint_values.size());
  msg.joint_values = state.joint_values;
  msg.grasp_id = state.grasp_id;
  return EncodeMessage(msg);
}

static bool DecodeGripperStateImpl(const void* data, size_t size, const Eigen::Isometry3d& T_C_B,
                                   GripperState* out, std::string* error) {
  if (!CheckBuffer(data, size, out, "gripper_state_t", error)) return false;
  // Recordings made before grasp_id carry gripper_state_v1_t's layout (and
  // fingerprint): read as grasp_id 0.
  const bool v1 = WireReader(data, size).Hash(graspfill::gripper_state_v1_t::getHash());
  WireReader r(data, size);
  int32_t num_joints;
  if (!r.Hash(v1 ? graspfill::gripper_state_v1_t::getHash() : graspfill::gripper_state_t::getHash()) ||
      !r.Skip(8 + 1 + 3 * 8 + 4 * 8 + 8) || !r.Count(&num_joints, 8) ||
      !r.Skip(8 * static_cast<size_t>(num_joints)) || (!v1 && !r.Skip(8)) || r.remaining() != 0) {
    SetError(error, "gripper_state_t: malformed message");
    return false;
  }
  thread_local graspfill::gripper_state_t msg{};
  // lcm-gen skips an array whose count is 0 without resizing it: clear
  // (keeping capacity) so nothing stale survives from the last message.
  msg.joint_values.clear();
  if (v1) {
    thread_local graspfill::gripper_state_v1_t old{};
    old.joint_values.clear();
    if (!DecodeMessage(data, size, &old, error)) return false;
    msg.utime = old.utime;
    msg.frame = old.frame;
    std::copy(old.position, old.position + 3, msg.position);
    std::copy(old.orientation, old.orientation + 4, msg.orientation);
    msg.opening_m = old.opening_m;
    msg.num_joints = old.num_joints;
    msg.joint_values.assign(old.joint_values.begin(), old.joint_values.end());
    msg.grasp_id = 0;
  } else if (!DecodeMessage(data, size, &msg, error)) {
    return false;
  }

  Eigen::Isometry3d T_F_G;
  if (!PoseFromWire("gripper_state_t", msg.position, msg.orientation, &T_F_G, error)) {
    return false;
  }
  if (!std::isfinite(msg.opening_m) || !AllFinite(msg.joint_values.data(), msg.num_joints)) {
    SetError(error, "gripper_state_t: opening or joint values not finite", MessageError::kBadValue);
    return false;
  }
  if (!UtimeInRange("gripper_state_t", msg.utime, error)) return false;
  if (msg.frame == graspfill::gripper_state_t::FRAME_CAMERA) {
    out->T_C_G = T_F_G;
  } else if (msg.frame == graspfill::gripper_state_t::FRAME_BASE) {
    out->T_C_G = T_C_B * T_F_G;
  } else {
    SetError(error, "gripper_state_t: unknown frame " + std::to_string(static_cast<int>(msg.frame)),
             MessageError::kBadValue);
    return false;
  }
  out->utime = msg.utime;
  out->opening_m = msg.opening_m;
  out->joint_values.assign(msg.joint_values.begin(), msg.joint_values.end());
  out->grasp_id = msg.grasp_id;
  return true;
}

bool DecodeGripperState(const void* data, size_t size, const Eigen::Isometry3d& T_C_B, GripperState* out,
                        std::string* error, MessageError* reason) {
  return WithReason(reason, [&] { return DecodeGripperStateImpl(data, size, T_C_B, out, error); });
}

}  // namespace graspfill::io
