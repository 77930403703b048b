// SPDX-License-Identifier: BSD-3-Clause
// collision_mesh_t <-> CollisionMeshMessage: the planner's mesh in G, its
// kind, whether it is watertight and how far the cloud lies outside it.
#include "graspfill/io/collision_mesh_message.hpp"

#include "wire.hpp"

#include <cmath>

#include <graspfill/collision_mesh_t.hpp>

namespace graspfill::io {
using namespace wire;
namespace {

// One vertex (3 float) or triangle (3 int32) on the wire [bytes].
constexpr size_t kElementBytes = 3 * 4;

// A vertex or triangle count that fits the bytes may still be over the
// message's own limit (16 M of each): refused before lcm-gen allocates.
bool WithinElementLimit(int32_t count) { return count <= kMaxCollisionMeshElements; }

}  // namespace

std::vector<uint8_t> EncodeCollisionMesh(const CollisionMeshMessage& m) {
  auto refuse = [](const std::string& why) { throw std::invalid_argument("EncodeCollisionMesh: " + why); };
  const size_t num_vertices = m.mesh.vertices.size();
  if (num_vertices > static_cast<size_t>(kMaxCollisionMeshElements) ||
      m.mesh.triangles.size() > static_cast<size_t>(kMaxCollisionMeshElements)) {
    refuse("more than " + std::to_string(kMaxCollisionMeshElements) + " vertices or triangles");
  }
  if (!std::isfinite(m.deviation_m) || m.deviation_m < 0.0) refuse("deviation_m not finite and >= 0");
  if (!m.T_C_G.matrix().allFinite()) refuse("T_C_G is not finite");
  if (m.frame_name.find('\0') != std::string::npos) refuse("frame_name has a NUL byte");
  graspfill::collision_mesh_t msg{};
  msg.utime = m.utime;
  msg.seq = m.seq;
  msg.grasp_id = m.grasp_id;
  msg.frame_name = m.frame_name;
  PoseToWire(m.T_C_G, msg.position, msg.orientation);
  msg.kind = m.kind == CollisionMeshKind::kConvexHull ? graspfill::collision_mesh_t::CONVEX_HULL
                                                      : graspfill::collision_mesh_t::DECIMATED;
  msg.watertight = m.watertight ? 1 : 0;
  msg.deviation_m = static_cast<float>(m.deviation_m);
  msg.num_vertices = static_cast<int32_t>(num_vertices);
  msg.vertices.reserve(num_vertices);
  for (const Eigen::Vector3f& v : m.mesh.vertices) {
    if (!v.allFinite()) refuse("a vertex is not finite");
    msg.vertices.push_back({v.x(), v.y(), v.z()});
  }
  msg.num_triangles = static_cast<int32_t>(m.mesh.triangles.size());
  msg.triangles.reserve(m.mesh.triangles.size());
  for (const Eigen::Vector3i& t : m.mesh.triangles) {
    if (t.minCoeff() < 0 || static_cast<size_t>(t.maxCoeff()) >= num_vertices) {
      refuse("a triangle's index is outside the " + std::to_string(num_vertices) + " vertices");
    }
    msg.triangles.push_back({t.x(), t.y(), t.z()});
  }
  return EncodeMessage(msg);
}

static bool DecodeCollisionMeshImpl(const void* data, size_t size, CollisionMeshMessage* out,
                                    std::string* error) {
  if (!CheckBuffer(data, size, out, "collision_mesh_t", error)) return false;
  // Walk the whole message (collision_mesh_t.lcm) before lcm-gen resizes
  // anything to the counts on the wire.
  {
    WireReader r(data, size);
    int32_t num_vertices = 0, num_triangles = 0;
    const bool ok = r.Hash(graspfill::collision_mesh_t::getHash()) && r.Skip(3 * 8) &&
                    r.SkipString() &&                     // utime, seq, grasp_id, frame_name
                    r.Skip(3 * 8 + 4 * 8 + 1 + 1 + 4) &&  // pose, kind, watertight, deviation_m
                    r.Count(&num_vertices, kElementBytes) && WithinElementLimit(num_vertices) &&
                    r.Skip(kElementBytes * static_cast<size_t>(num_vertices)) &&
                    r.Count(&num_triangles, kElementBytes) && WithinElementLimit(num_triangles) &&
                    r.Skip(kElementBytes * static_cast<size_t>(num_triangles)) && r.remaining() == 0;
    if (!ok) {
      SetError(error, "collision_mesh_t: malformed message");
      return false;
    }
  }
  thread_local graspfill::collision_mesh_t msg{};
  // As for gripper_state_t: empty arrays are not resized by lcm-gen.
  msg.vertices.clear();
  msg.triangles.clear();
  if (!DecodeMessage(data, size, &msg, error)) return false;
  if (!UtimeInRange("collision_mesh_t", msg.utime, error)) return false;
  Eigen::Isometry3d T_C_G;
  if (!PoseFromWire("collision_mesh_t", msg.position, msg.orientation, &T_C_G, error)) return false;
  if (msg.kind != graspfill::collision_mesh_t::DECIMATED &&
      msg.kind != graspfill::collision_mesh_t::CONVEX_HULL) {
    SetError(error, "collision_mesh_t: unknown kind " + std::to_string(static_cast<int>(msg.kind)),
             MessageError::kBadValue);
    return false;
  }
  if (msg.watertight != 0 && msg.watertight != 1) {
    SetError(error,
             "collision_mesh_t: watertight must be 0 or 1, not " +
                 std::to_string(static_cast<int>(msg.watertight)),
             MessageError::kBadValue);
    return false;
  }
  if (!std::isfinite(msg.deviation_m) || msg.deviation_m < 0.0f) {
    SetError(error,
             "collision_mesh_t: deviation_m " + std::to_string(msg.deviation_m) + " is not finite and >= 0",
             MessageError::kBadValue);
    return false;
  }
  // Into scratch first: `out` is left as it was on a failure.
  thread_local TriangleMesh mesh;
  mesh.vertices.clear();
  mesh.triangles.clear();
  for (const std::vector<float>& v : msg.vertices) {
    const Eigen::Vector3f p(v[0], v[1], v[2]);
    if (!p.allFinite()) {
      SetError(error, "collision_mesh_t: a vertex is not finite", MessageError::kBadValue);
      return false;
    }
    mesh.vertices.push_back(p);
  }
  for (const std::vector<int32_t>& t : msg.triangles) {
    const Eigen::Vector3i ijk(t[0], t[1], t[2]);
    if (ijk.minCoeff() < 0 || ijk.maxCoeff() >= msg.num_vertices) {
      SetError(error,
               "collision_mesh_t: a triangle's index is outside the " + std::to_string(msg.num_vertices) +
                   " vertices",
               MessageError::kBadValue);
      return false;
    }
    mesh.triangles.push_back(ijk);
  }
  out->utime = msg.utime;
  out->seq = msg.seq;
  out->grasp_id = msg.grasp_id;
  out->frame_name = msg.frame_name;
  out->T_C_G = T_C_G;
  out->mesh.vertices.swap(mesh.vertices);
  out->mesh.triangles.swap(mesh.triangles);
  out->kind = msg.kind == graspfill::collision_mesh_t::CONVEX_HULL ? CollisionMeshKind::kConvexHull
                                                                   : CollisionMeshKind::kDecimated;
  out->watertight = msg.watertight == 1;
  out->deviation_m = msg.deviation_m;
  return true;
}

bool DecodeCollisionMesh(const void* data, size_t size, CollisionMeshMessage* out, std::string* error,
                         MessageError* reason) {
  return WithReason(reason, [&] { return DecodeCollisionMeshImpl(data, size, out, error); });
}

}  // namespace graspfill::io
