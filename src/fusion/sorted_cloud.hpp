// SPDX-License-Identifier: BSD-3-Clause
// The fused cloud in a canonical order: what every TSDF extraction of the
// fusion module writes, so that its bytes depend neither on the order of
// Open3D's block hash map nor on a cache's.
//
// Private to the fusion module (and its internal tool library).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::fusion {

/// Replaces *cloud's points with `points` (and `normals`, normalized, when
/// there is one per point), sorted lexicographically by point, normals
/// breaking ties; every point observed.
void WriteSortedCloud(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& normals,
                      ObjectCloud* cloud);

}  // namespace graspfill::fusion
