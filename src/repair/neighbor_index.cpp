#include "graspfill/repair/neighbor_index.hpp"

#include <open3d/geometry/KDTreeFlann.h>

#include <stdexcept>

namespace graspfill::repair {

struct NeighborIndex::Impl {
  Eigen::MatrixXd data;  // 3 x N, the layout KDTreeFlann reads
  open3d::geometry::KDTreeFlann tree;
};

NeighborIndex::NeighborIndex(const PointList& points)
    : points_(points), impl_(std::make_unique<Impl>()) {
  if (points.empty()) throw std::invalid_argument("NeighborIndex: empty cloud");
  impl_->data.resize(3, static_cast<Eigen::Index>(points.size()));
  for (size_t i = 0; i < points.size(); ++i) {
    impl_->data.col(static_cast<Eigen::Index>(i)) = points[i].cast<double>();
  }
  impl_->tree.SetMatrixData(impl_->data);
}

NeighborIndex::~NeighborIndex() = default;

void NeighborIndex::Knn(const Eigen::Vector3f& query, int k, std::vector<int>* indices,
                        std::vector<double>* squared_distances) const {
  std::vector<double> d2;
  impl_->tree.SearchKNN(Eigen::Vector3d(query.cast<double>()), k, *indices,
                        squared_distances ? *squared_distances : d2);
}

void NeighborIndex::Radius(const Eigen::Vector3f& query, double radius_m,
                           std::vector<int>* indices,
                           std::vector<double>* squared_distances) const {
  std::vector<double> d2;
  impl_->tree.SearchRadius(Eigen::Vector3d(query.cast<double>()), radius_m, *indices,
                           squared_distances ? *squared_distances : d2);
}

}  // namespace graspfill::repair
