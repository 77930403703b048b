// SPDX-License-Identifier: BSD-3-Clause
// collision_mesh_t decoder on arbitrary bytes, with an encode round trip.
#include <cstdint>
#include <string>

#include "fuzz_check.hpp"
#include "graspfill/io/collision_mesh_message.hpp"

using namespace graspfill;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  io::CollisionMeshMessage mesh;
  std::string error;
  io::MessageError reason;
  if (!io::DecodeCollisionMesh(data, size, &mesh, &error, &reason)) {
    FUZZ_CHECK(reason != io::MessageError::kNone && !error.empty());
    return 0;
  }
  FUZZ_CHECK(mesh.T_C_G.matrix().allFinite());
  FUZZ_CHECK(mesh.utime >= 0 && mesh.utime <= io::kMaxUtime);
  FUZZ_CHECK(mesh.deviation_m >= 0.0);
  for (const Eigen::Vector3i& t : mesh.mesh.triangles) {
    FUZZ_CHECK(t.minCoeff() >= 0 && static_cast<size_t>(t.maxCoeff()) < mesh.mesh.vertices.size());
  }
  // What decodes is a mesh the encoder takes, and it comes back exactly
  // (vertices and deviation are floats on the wire both ways).
  const std::vector<uint8_t> bytes = io::EncodeCollisionMesh(mesh);
  io::CollisionMeshMessage back;
  FUZZ_CHECK(io::DecodeCollisionMesh(bytes.data(), bytes.size(), &back, &error));
  FUZZ_CHECK(back.utime == mesh.utime && back.seq == mesh.seq && back.grasp_id == mesh.grasp_id);
  FUZZ_CHECK(back.frame_name == mesh.frame_name);
  FUZZ_CHECK(back.mesh.vertices == mesh.mesh.vertices && back.mesh.triangles == mesh.mesh.triangles);
  FUZZ_CHECK(back.kind == mesh.kind && back.watertight == mesh.watertight);
  FUZZ_CHECK(back.deviation_m == mesh.deviation_m);
  const double scale = 1.0 + mesh.T_C_G.translation().norm();
  FUZZ_CHECK((back.T_C_G.matrix() - mesh.T_C_G.matrix()).cwiseAbs().maxCoeff() <= 1e-9 * scale);
  return 0;
}
