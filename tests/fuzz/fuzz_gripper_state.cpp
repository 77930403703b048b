// SPDX-License-Identifier: BSD-3-Clause
// gripper_state_t decoder on arbitrary bytes, with an encode round trip.
#include <cmath>
#include <cstdint>
#include <string>

#include "fuzz_check.hpp"
#include "graspfill/io/messages.hpp"

using namespace graspfill;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Eigen::Isometry3d T_C_B = Eigen::Isometry3d::Identity();
  T_C_B.translation() = Eigen::Vector3d(0.1, -0.2, 0.3);
  GripperState state;
  std::string error;
  io::MessageError reason;
  if (!io::DecodeGripperState(data, size, T_C_B, &state, &error, &reason)) {
    FUZZ_CHECK(reason != io::MessageError::kNone && !error.empty());
    return 0;
  }
  FUZZ_CHECK(state.T_C_G.matrix().allFinite());
  FUZZ_CHECK(state.utime >= 0 && state.utime <= io::kMaxUtime);
  const std::vector<uint8_t> bytes = io::EncodeGripperState(state);
  GripperState back;
  FUZZ_CHECK(io::DecodeGripperState(bytes.data(), bytes.size(), T_C_B, &back, &error));
  FUZZ_CHECK(back.utime == state.utime);
  FUZZ_CHECK(back.opening_m == state.opening_m);
  FUZZ_CHECK(back.joint_values == state.joint_values);
  const double scale = 1.0 + state.T_C_G.translation().norm();
  FUZZ_CHECK((back.T_C_G.matrix() - state.T_C_G.matrix()).cwiseAbs().maxCoeff() <= 1e-9 * scale);
  return 0;
}
