// SPDX-License-Identifier: BSD-3-Clause
// mesh_containment MESH CLOUD.ply: how well a collision mesh file holds a
// cloud, for docs/measurements (any graspfill's --mesh-out, before or
// after): its triangles, Open3D's watertight test, and the cloud points
// outside it (count, p99 and max of their distance, inside points as 0),
// as one JSON line. Exit 1 with a message on a file it cannot read.

#include <cstdio>
#include <exception>
#include <string>

#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/mesh_deviation.hpp"
#include "open3d_watertight.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s MESH.{ply,stl,obj} CLOUD.ply\n", argv[0]);
    return 1;
  }
  try {
    const graspfill::TriangleMesh mesh = graspfill::io::ReadMesh(argv[1]);
    const graspfill::ObjectCloud cloud = graspfill::io::ReadCloudPly(argv[2]);
    // Merged first: an STL repeats each vertex per triangle.
    const bool watertight = graspfill::testing::Open3dWatertight(mesh, true);
    const graspfill::mesh::OutsideDeviation d =
        graspfill::mesh::SummarizeOutside(graspfill::mesh::OutsideDistances(mesh, cloud.points_G));
    std::printf(
        "{\"triangles\": %zu, \"watertight\": %s, \"points\": %zu, \"points_outside\": %lld, "
        "\"outside_p99_mm\": %.3f, \"outside_max_mm\": %.3f}\n",
        mesh.triangles.size(), watertight ? "true" : "false", cloud.size(),
        static_cast<long long>(d.points_outside), d.p99_m * 1e3, d.max_m * 1e3);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mesh_containment: %s\n", e.what());
    return 1;
  }
  return 0;
}
