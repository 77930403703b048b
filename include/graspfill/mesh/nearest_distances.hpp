// SPDX-License-Identifier: BSD-3-Clause
// Nearest-neighbour distances from one cloud to another (Open3D's KD-tree):
// the mesh deviation's surface-to-cloud side, and the cloud metrics.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace graspfill::mesh {

/// Throws std::invalid_argument if `cloud` is empty or holds a non-finite
/// coordinate; the message names the cloud (`name`, e.g. "predicted") and
/// the point's index. An empty cloud leaves a mean undefined, a NaN makes
/// the KD-tree answer garbage.
void CheckCloud(const std::vector<Eigen::Vector3f>& cloud, const std::string& name);

/// For every point of `from`, the squared Euclidean distance to its nearest
/// neighbour in `to` [m^2], in the order of `from`. Squared values keep an
/// exact geometry exact where a sum of squares follows (no sqrt and square
/// round trip).
/// @throws std::invalid_argument as CheckCloud, for either cloud.
std::vector<double> NearestSquaredDistances(const std::vector<Eigen::Vector3f>& from,
                                            const std::vector<Eigen::Vector3f>& to);

/// NearestSquaredDistances' square roots [m].
std::vector<double> NearestDistances(const std::vector<Eigen::Vector3f>& from,
                                     const std::vector<Eigen::Vector3f>& to);

}  // namespace graspfill::mesh
