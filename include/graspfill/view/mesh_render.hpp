// SPDX-License-Identifier: BSD-3-Clause
// Pictures of triangle meshes for people (a collision mesh, a claw): each
// triangle filled through a z-buffer, shaded by its normal, with the same
// orthographic camera as view/cloud_render.hpp so that a mesh and a cloud
// of one picture compare at one scale.
//
// Pure functions; reentrant, any thread.
#pragma once

#include <vector>

#include "graspfill/types.hpp"
#include "graspfill/view/cloud_render.hpp"

namespace graspfill::view {

/// Draws `mesh` into the `size_px` x `size_px` square of *image whose
/// top-left pixel is (x0, y0), over what is there. Every pixel whose centre
/// a triangle covers takes the nearest triangle's colour: the provenance
/// colour of its first vertex (`vertex_provenance`, one per vertex, or
/// empty: observed) times a shade in [0.45, 1] by the angle of its normal
/// to the view (1 facing the camera; either side, as winding is not
/// trusted). Triangles with a non-finite vertex or an index out of range
/// are skipped.
void RenderMeshView(const TriangleMesh& mesh, const std::vector<Provenance>& vertex_provenance,
                    const Framing& framing, const ViewAngle& angle, int x0, int y0, int size_px,
                    RgbImage* image);

}  // namespace graspfill::view
