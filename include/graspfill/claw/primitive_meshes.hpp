// SPDX-License-Identifier: BSD-3-Clause
// Closed triangle meshes of URDF's geometric primitives, centred at the
// origin as URDF places them (a cylinder's axis along z).
#pragma once

#include <Eigen/Core>

#include "graspfill/types.hpp"

namespace graspfill::claw {

/// A box of this size [m], outward-facing triangles.
TriangleMesh BoxMesh(const Eigen::Vector3d& size_m);
/// A cylinder along z, `segments` facets around.
TriangleMesh CylinderMesh(double radius_m, double length_m, int segments = 32);
/// A UV sphere, `segments` facets around and segments / 2 bands.
TriangleMesh SphereMesh(double radius_m, int segments = 32);

}  // namespace graspfill::claw
