// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/mesh/nearest_distances.hpp"

#include <open3d/geometry/KDTreeFlann.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace graspfill::mesh {

void CheckCloud(const std::vector<Eigen::Vector3f>& cloud, const std::string& name) {
  if (cloud.empty()) {
    throw std::invalid_argument("graspfill: the " + name + " cloud is empty");
  }
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud[i].allFinite()) {
      std::ostringstream msg;
      msg << "graspfill: the " << name << " cloud has a non-finite coordinate at point " << i << " ("
          << cloud[i].x() << ", " << cloud[i].y() << ", " << cloud[i].z() << ")";
      throw std::invalid_argument(msg.str());
    }
  }
}

std::vector<double> NearestSquaredDistances(const std::vector<Eigen::Vector3f>& from,
                                            const std::vector<Eigen::Vector3f>& to) {
  CheckCloud(from, "'from'");
  CheckCloud(to, "'to'");
  Eigen::MatrixXd data(3, static_cast<Eigen::Index>(to.size()));
  for (size_t i = 0; i < to.size(); ++i) {
    data.col(static_cast<Eigen::Index>(i)) = to[i].cast<double>();
  }
  open3d::geometry::KDTreeFlann tree;
  if (!tree.SetMatrixData(data)) {
    throw std::runtime_error("graspfill: building the KD-tree failed");
  }
  std::vector<double> d2(from.size());
  std::vector<int> index(1);
  std::vector<double> dist2(1);
  for (size_t i = 0; i < from.size(); ++i) {
    const Eigen::Vector3d query = from[i].cast<double>();
    if (tree.SearchKNN(query, 1, index, dist2) < 1) {
      throw std::runtime_error("graspfill: the KD-tree search found nothing");
    }
    d2[i] = dist2[0];
  }
  return d2;
}

std::vector<double> NearestDistances(const std::vector<Eigen::Vector3f>& from,
                                     const std::vector<Eigen::Vector3f>& to) {
  std::vector<double> d = NearestSquaredDistances(from, to);
  for (double& x : d) x = std::sqrt(x);
  return d;
}

}  // namespace graspfill::mesh
