// SPDX-License-Identifier: BSD-3-Clause
// session_description_t decoder on arbitrary bytes, with an encode round trip.
#include <cstdint>
#include <string>

#include "fuzz_check.hpp"
#include "graspfill/io/messages.hpp"

using namespace graspfill;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  io::SessionDescription session;
  std::string error;
  io::MessageError reason;
  if (!io::DecodeSessionDescription(data, size, &session, &error, &reason)) {
    FUZZ_CHECK(reason != io::MessageError::kNone && !error.empty());
    return 0;
  }
  const std::vector<uint8_t> bytes = io::EncodeSessionDescription(session);
  io::SessionDescription back;
  FUZZ_CHECK(io::DecodeSessionDescription(bytes.data(), bytes.size(), &back, &error));
  FUZZ_CHECK(back.utime == session.utime);
  FUZZ_CHECK(back.claw_kind == session.claw_kind);
  FUZZ_CHECK(back.claw_name == session.claw_name && back.claw_text == session.claw_text);
  FUZZ_CHECK(back.claw_source == session.claw_source && back.claw_mesh_root == session.claw_mesh_root);
  FUZZ_CHECK(back.software_version == session.software_version);
  FUZZ_CHECK(back.intrinsics == session.intrinsics);
  FUZZ_CHECK(back.workspace_G.has_value() == session.workspace_G.has_value());
  FUZZ_CHECK(back.voxel_m == session.voxel_m);
  const double scale = 1.0 + session.T_C_B.translation().norm();
  FUZZ_CHECK((back.T_C_B.matrix() - session.T_C_B.matrix()).cwiseAbs().maxCoeff() <= 1e-9 * scale);
  return 0;
}
