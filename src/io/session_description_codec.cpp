// SPDX-License-Identifier: BSD-3-Clause
// session_description_t <-> SessionDescription, and the limits a session
// must keep.
#include "graspfill/io/messages.hpp"

#include "wire.hpp"

#include <graspfill/session_description_t.hpp>
#include <graspfill/version.hpp>

namespace graspfill::io {
using namespace wire;

namespace {

// The checks shared by the encoder (caller misuse) and the decoder (bad
// input) on the value type; T_C_B's quaternion is checked on the wire.
bool CheckSession(const SessionDescription& s, std::string* error) {
  const char* type = "session_description_t";
  if (s.claw_name.empty()) {
    SetError(error, std::string(type) + ": empty claw_name");
    return false;
  }
  if (!IsPlainClawName(s.claw_name)) {
    SetError(error,
             std::string(type) + ": claw_name '" + Printable(s.claw_name, 80) +
                 "' is not a plain name (1..256 bytes, no '/', '\\' or control "
                 "characters, not '.' or '..')",
             MessageError::kBadClawName);
    return false;
  }
  if (!s.T_C_B.matrix().allFinite()) {
    SetError(error, std::string(type) + ": T_C_B is not finite");
    return false;
  }
  if (s.intrinsics) {
    const CameraIntrinsics& K = *s.intrinsics;
    if (K.width <= 0 || K.height <= 0 || int64_t{K.width} * K.height > kMaxDepthPixels) {
      SetError(error,
               std::string(type) + ": bad intrinsics override size " + std::to_string(K.width) + "x" +
                   std::to_string(K.height),
               MessageError::kBadSize);
      return false;
    }
    std::string why;
    if (!IntrinsicsInRange(K, &why)) {
      SetError(error, std::string(type) + ": bad intrinsics override (" + why + ")",
               MessageError::kBadIntrinsics);
      return false;
    }
  }
  if (s.workspace_G) {
    const Eigen::AlignedBox3d& box = *s.workspace_G;
    if (!box.min().allFinite() || !box.max().allFinite() || !(box.min().array() < box.max().array()).all()) {
      SetError(error, std::string(type) + ": workspace box must be finite with min < max");
      return false;
    }
  }
  if (!std::isfinite(s.voxel_m) || s.voxel_m < 0.0) {
    SetError(error, std::string(type) + ": voxel_m must be finite and >= 0 (0 = default)");
    return false;
  }
  return true;
}

}  // namespace

bool IsPlainClawName(const std::string& name) {
  if (name.empty() || name.size() > 256 || name == "." || name == "..") return false;
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '/' || c == '\\' || u < 0x20 || u == 0x7f) return false;
  }
  return true;
}

bool SessionWithinLimits(const SessionDescription& s, std::string* why) {
  auto fail = [&](const std::string& text) {
    if (why != nullptr) *why = text;
    return false;
  };
  const auto number = FormatLimit;
  if (s.workspace_G) {
    static const char* kAxes = "xyz";
    for (int k = 0; k < 3; ++k) {
      for (const double v : {s.workspace_G->min()[k], s.workspace_G->max()[k]}) {
        // Written as an "in range" test so that NaN fails it.
        if (!(v >= -kMaxWorkspaceM && v <= kMaxWorkspaceM)) {
          return fail("asks for a workspace box with " + std::string(1, kAxes[k]) + " " + number(v) +
                      " m, outside -" + number(kMaxWorkspaceM) + ".." + number(kMaxWorkspaceM) + " m");
        }
      }
    }
  }
  if (s.voxel_m != 0.0 && !(s.voxel_m >= kMinVoxelM && s.voxel_m <= kMaxVoxelM)) {
    return fail("asks for a voxel of " + number(s.voxel_m) + " m, outside " + number(kMinVoxelM) + ".." +
                number(kMaxVoxelM) + " m");
  }
  const Eigen::Vector3d t = s.T_C_B.translation();
  if (!(t.cwiseAbs().maxCoeff() <= kMaxHandEyeTranslationM)) {
    return fail("asks for a hand-eye T_C_B translated by " + number(t.cwiseAbs().maxCoeff()) + " m, beyond " +
                number(kMaxHandEyeTranslationM) + " m");
  }
  return true;
}

std::string SoftwareVersion() { return std::string("graspfill ") + GRASPFILL_VERSION; }

std::vector<uint8_t> EncodeSessionDescription(const SessionDescription& session) {
  std::string error;
  if (!CheckSession(session, &error)) {
    throw std::invalid_argument("EncodeSessionDescription: " + error);
  }
  using Msg = graspfill::session_description_t;
  Msg msg{};
  msg.utime = session.utime;
  msg.software_version = session.software_version;
  switch (session.claw_kind) {
    case SessionClawKind::kBuiltin:
      msg.claw_kind = Msg::CLAW_BUILTIN;
      break;
    case SessionClawKind::kDescription:
      msg.claw_kind = Msg::CLAW_DESCRIPTION;
      break;
    case SessionClawKind::kUrdf:
      msg.claw_kind = Msg::CLAW_URDF;
      break;
  }
  msg.claw_name = session.claw_name;
  msg.claw_text = session.claw_text;
  msg.claw_source = session.claw_source;
  msg.claw_mesh_root = session.claw_mesh_root;
  PoseToWire(session.T_C_B, msg.T_C_B_position, msg.T_C_B_orientation);
  if (session.intrinsics) {
    const CameraIntrinsics& K = *session.intrinsics;
    msg.has_intrinsics = 1;
    msg.width = K.width;
    msg.height = K.height;
    msg.fx = K.fx;
    msg.fy = K.fy;
    msg.cx = K.cx;
    msg.cy = K.cy;
  }
  if (session.workspace_G) {
    msg.has_workspace_box = 1;
    for (int k = 0; k < 3; ++k) {
      msg.workspace_min[k] = session.workspace_G->min()[k];
      msg.workspace_max[k] = session.workspace_G->max()[k];
    }
  }
  msg.voxel_m = session.voxel_m;
  return EncodeMessage(msg);
}

static bool DecodeSessionDescriptionImpl(const void* data, size_t size, SessionDescription* out,
                                         std::string* error) {
  using Msg = graspfill::session_description_t;
  if (!CheckBuffer(data, size, out, "session_description_t", error)) return false;
  // Layout: session_description_t.lcm. Every string length is checked
  // against the bytes left before the generated decoder reads it.
  {
    WireReader r(data, size);
    const bool ok = r.Hash(Msg::getHash()) && r.Skip(8) && r.SkipString() &&  // version
                    r.Skip(1) && r.SkipString() && r.SkipString() &&          // name, text
                    r.SkipString() && r.SkipString() &&                       // source, root
                    r.Skip(7 * 8) && r.Skip(1 + 2 * 4 + 4 * 8) &&             // T_C_B, K
                    r.Skip(1 + 6 * 8) && r.Skip(8) && r.remaining() == 0;     // box, voxel
    if (!ok) {
      SetError(error, "session_description_t: malformed message");
      return false;
    }
  }
  Msg msg{};
  if (!DecodeMessage(data, size, &msg, error)) return false;

  SessionDescription s;
  s.utime = msg.utime;
  s.software_version = msg.software_version;
  if (msg.claw_kind == Msg::CLAW_BUILTIN) {
    s.claw_kind = SessionClawKind::kBuiltin;
  } else if (msg.claw_kind == Msg::CLAW_DESCRIPTION) {
    s.claw_kind = SessionClawKind::kDescription;
  } else if (msg.claw_kind == Msg::CLAW_URDF) {
    s.claw_kind = SessionClawKind::kUrdf;
  } else {
    SetError(error,
             "session_description_t: unknown claw_kind " + std::to_string(static_cast<int>(msg.claw_kind)));
    return false;
  }
  s.claw_name = msg.claw_name;
  s.claw_text = msg.claw_text;
  s.claw_source = msg.claw_source;
  s.claw_mesh_root = msg.claw_mesh_root;
  if (!PoseFromWire("session_description_t: T_C_B", msg.T_C_B_position, msg.T_C_B_orientation, &s.T_C_B,
                    error)) {
    return false;
  }
  if ((msg.has_intrinsics != 0 && msg.has_intrinsics != 1) ||
      (msg.has_workspace_box != 0 && msg.has_workspace_box != 1)) {
    SetError(error, "session_description_t: has_intrinsics and has_workspace_box must be 0 or 1");
    return false;
  }
  if (msg.has_intrinsics == 1) {
    s.intrinsics = CameraIntrinsics{msg.width, msg.height, msg.fx, msg.fy, msg.cx, msg.cy};
  }
  if (msg.has_workspace_box == 1) {
    s.workspace_G = Eigen::AlignedBox3d(
        Eigen::Vector3d(msg.workspace_min[0], msg.workspace_min[1], msg.workspace_min[2]),
        Eigen::Vector3d(msg.workspace_max[0], msg.workspace_max[1], msg.workspace_max[2]));
  }
  s.voxel_m = msg.voxel_m;
  if (!CheckSession(s, error)) return false;
  *out = std::move(s);
  return true;
}

bool DecodeSessionDescription(const void* data, size_t size, SessionDescription* out, std::string* error,
                              MessageError* reason) {
  return WithReason(reason, [&] { return DecodeSessionDescriptionImpl(data, size, out, error); });
}

}  // namespace graspfill::io
