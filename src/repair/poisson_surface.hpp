// SPDX-License-Identifier: BSD-3-Clause
// Open3D's screened Poisson surface for the claw-hole fill (the paper's
// surface, --mode paper) and the sampler of its mesh. Internal to the
// repair library.
#pragma once

#include <memory>
#include <vector>

#include "gap_test.hpp"
#include "hole_fill.hpp"

namespace open3d::geometry {
class TriangleMesh;
}

namespace graspfill::repair::fill {

struct PoissonSurface {
  std::shared_ptr<open3d::geometry::TriangleMesh> mesh;
  std::vector<double> densities;
  double cell_m{0.0};  ///< edge of the finest octree cell
};

PoissonSurface ReconstructPoisson(const PointList& points, const std::vector<int>& subset,
                                  const std::vector<Eigen::Vector3f>& normals, int depth, double scale);

// Samples, at `density` per m^2, the triangles that reach into `region`
// (in `frame`), whose vertices are all kept (`keep_vertex`, may be null),
// and that face within acos(cos_max_angle) of frame.n when `check_facing`
// (the mesh winds outwards, as its input normals point; this drops the far
// side of a closed Poisson surface); keeps the samples inside the region
// that pass the gap test.
void SampleMesh(const open3d::geometry::TriangleMesh& mesh, const HoleFrame& frame, const FillRegion& region,
                bool check_facing, double cos_max_angle, const std::vector<bool>* keep_vertex, double density,
                Rng* rng, GapTest* gap, PointList* out);

}  // namespace graspfill::repair::fill
