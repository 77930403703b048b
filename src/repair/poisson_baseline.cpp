// SPDX-License-Identifier: BSD-3-Clause
#include "poisson_baseline.hpp"

#include <open3d/geometry/TriangleMesh.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "gap_test.hpp"
#include "graspfill/core/require.hpp"
#include "hole_fill.hpp"
#include "poisson_surface.hpp"

namespace graspfill::repair {

using namespace fill;

void PoissonFillConfig::Validate() const {
  const std::string p = "PoissonFillConfig.";
  Require(poisson_depth >= 2 && poisson_depth <= 12, p + "poisson_depth must be in [2, 12]");
  Require(poisson_scale >= 1.0 && poisson_scale <= 16.0, p + "poisson_scale must be in [1, 16]");
  Require(normal_knn >= 3 && normal_knn <= 200, p + "normal_knn must be in [3, 200]");
  Require(density_trim_quantile >= 0.0 && density_trim_quantile < 1.0,
          p + "density_trim_quantile must be in [0, 1)");
  Require(crop_pad_fraction >= 0.0 && crop_pad_fraction <= 10.0, p + "crop_pad_fraction must be in [0, 10]");
  Require(min_gap_d >= 0.0 && min_gap_d <= 100.0, p + "min_gap_d must be in [0, 100]");
  Require(fill_density_factor > 0.0 && fill_density_factor <= 100.0,
          p + "fill_density_factor must be in (0, 100]");
}

PointList PoissonFillAll(const PointList& points, const PoissonFillConfig& config,
                         const std::vector<Eigen::Vector3f>* normals, const NeighborIndex* index) {
  config.Validate();
  CheckInputs(points, normals, index, "PoissonFillAll");
  PointList out;
  // Too few points for normals and a meaningful surface: nothing to fill.
  if (points.size() < static_cast<size_t>(2 * config.normal_knn)) return out;
  std::unique_ptr<NeighborIndex> own_index;
  if (index == nullptr) {
    own_index = std::make_unique<NeighborIndex>(points);
    index = own_index.get();
  }
  std::vector<int> all(points.size());
  for (size_t i = 0; i < points.size(); ++i) all[i] = static_cast<int>(i);
  const Spacing spacing = EstimateSpacing(*index, all, 2000);
  if (spacing.mean_nn_m <= 0.0 || spacing.density_per_m2 <= 0.0) return out;
  const double d = spacing.mean_nn_m;

  const std::vector<Eigen::Vector3f> n =
      normals != nullptr ? *normals : EstimateNormals(*index, all, config.normal_knn, Centroid(points));
  const PoissonSurface surface =
      ReconstructPoisson(points, all, n, config.poisson_depth, config.poisson_scale);
  const open3d::geometry::TriangleMesh& mesh = *surface.mesh;
  if (mesh.triangles_.empty()) return out;

  double threshold = -std::numeric_limits<double>::infinity();
  if (config.density_trim_quantile > 0.0 && !surface.densities.empty()) {
    std::vector<double> sorted = surface.densities;
    const auto k = static_cast<size_t>(config.density_trim_quantile * static_cast<double>(sorted.size() - 1));
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(k), sorted.end());
    threshold = sorted[k];
  }
  Box bounds;
  bounds.setEmpty();
  for (const Eigen::Vector3f& p : points) bounds.extend(p);
  const double pad = config.crop_pad_fraction * bounds.sizes().maxCoeff();
  FillRegion crop;  // in the identity frame
  crop.lo = bounds.min().cast<double>() - Eigen::Vector3d::Constant(pad);
  crop.hi = bounds.max().cast<double>() + Eigen::Vector3d::Constant(pad);
  std::vector<bool> keep(mesh.vertices_.size());
  for (size_t v = 0; v < keep.size(); ++v) {
    const bool dense = v >= surface.densities.size() || surface.densities[v] >= threshold;
    keep[v] = dense && crop.Contains(mesh.vertices_[v]);
  }
  GapTest gap(*index, nullptr, config.min_gap_d * d);
  Rng rng(MixSeed(config.seed, 0));
  SampleMesh(mesh, HoleFrame{}, crop, false, -1.0, &keep, spacing.density_per_m2 * config.fill_density_factor,
             &rng, &gap, &out);
  return out;
}

}  // namespace graspfill::repair
