// SPDX-License-Identifier: BSD-3-Clause
// An object's mesh as the synthesizer takes it (`synth --mesh`, `bench
// repair --objects`): read by io::ReadMesh (PLY, OBJ, STL), scaled into
// meters, its up axis turned onto +z.
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "graspfill/io/ply.hpp"
#include "graspfill/types.hpp"

namespace graspfill::cli {

/// Wider than this [m], a mesh is most likely not in meters, and no claw
/// here holds it.
constexpr double kMaxObjectExtentM = 0.5;

/// `path`'s mesh, every coordinate times `scale`, then (`y_up`) turned by
/// +90 deg about x so that its +y is +z.
/// @throws std::runtime_error (with the path) as io::ReadMesh does.
inline TriangleMesh ReadObjectMesh(const std::string& path, double scale = 1.0, bool y_up = false) {
  TriangleMesh mesh = io::ReadMesh(path);
  for (Eigen::Vector3f& v : mesh.vertices) v *= static_cast<float>(scale);
  if (y_up) {
    mesh = mesh.Transformed(
        Eigen::Isometry3d(Eigen::AngleAxisd(0.5 * 3.14159265358979323846, Eigen::Vector3d::UnitX())));
  }
  return mesh;
}

}  // namespace graspfill::cli
