// SPDX-License-Identifier: BSD-3-Clause
#include "hole_fill.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "geometry/plane_fit.hpp"

namespace graspfill::repair::fill {

void CheckFinite(const PointList& points, const char* what) {
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      throw std::invalid_argument(std::string(what) + ": non-finite coordinate at index " +
                                  std::to_string(i));
    }
  }
}

void CheckInputs(const PointList& points, const std::vector<Eigen::Vector3f>* normals,
                 const NeighborIndex* index, const char* what) {
  CheckFinite(points, what);
  if (normals != nullptr) {
    if (normals->size() != points.size()) {
      throw std::invalid_argument(std::string(what) + ": " + std::to_string(normals->size()) +
                                  " normals for " + std::to_string(points.size()) + " points");
    }
    CheckFinite(*normals, what);
  }
  if (index != nullptr) {
    if (&index->points() != &points) {
      throw std::invalid_argument(std::string(what) +
                                  ": the neighbour index must be built over the same cloud");
    }
  }
}

uint64_t MixSeed(uint64_t seed, uint64_t stream) {
  // SplitMix64 of the pair: neighbouring streams look independent.
  return SplitMix64(seed ^ (stream * 0x9e3779b97f4a7c15ULL + 0x632be59bd9b4e019ULL));
}

Spacing EstimateSpacing(const NeighborIndex& index, const std::vector<int>& subset, size_t max_queries) {
  constexpr int kK = 8;
  Spacing out;
  if (subset.empty()) return out;
  const size_t stride = std::max<size_t>(1, subset.size() / max_queries);
  std::vector<int> nn;
  std::vector<double> d2;
  double nn_sum = 0.0, rk2_sum = 0.0;
  int count = 0;
  for (size_t i = 0; i < subset.size(); i += stride) {
    index.Knn(index.points()[subset[i]], kK + 1, &nn, &d2);
    if (static_cast<int>(d2.size()) < kK + 1) continue;
    nn_sum += std::sqrt(d2[1]);  // d2[0] is the point itself
    rk2_sum += d2[kK];
    ++count;
  }
  if (count == 0 || rk2_sum <= 0.0) return out;
  out.mean_nn_m = nn_sum / count;
  out.density_per_m2 = kK / (M_PI * rk2_sum / count);
  return out;
}

std::vector<Eigen::Vector3f> EstimateNormals(const NeighborIndex& index, const std::vector<int>& subset,
                                             int k, const Eigen::Vector3f& centre) {
  const PointList& points = index.points();
  std::vector<Eigen::Vector3f> normals(subset.size());
  // One batch: the same neighbours as a query each, for less.
  const KnnTable table = index.KnnOf(subset, k);
  for (size_t i = 0; i < subset.size(); ++i) {
    const int* nn = table.Row(i);
    const auto neighbour = [&](size_t j) -> Eigen::Vector3d { return points[nn[j]].cast<double>(); };
    Eigen::Vector3f n =
        geometry::FitPlane(static_cast<size_t>(table.k), neighbour, geometry::EigenSolve::kClosedForm)
            .normal.cast<float>();
    if (n.dot(points[subset[i]] - centre) < 0.0f) n = -n;
    normals[i] = n;
  }
  return normals;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

std::vector<int> Thin(const std::vector<int>& indices, size_t max_count) {
  if (indices.size() <= max_count) return indices;
  const size_t stride = (indices.size() + max_count - 1) / max_count;
  std::vector<int> out;
  for (size_t i = 0; i < indices.size(); i += stride) out.push_back(indices[i]);
  return out;
}

Eigen::Vector3f Centroid(const PointList& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : points) sum += p.cast<double>();
  return (sum / static_cast<double>(std::max<size_t>(1, points.size()))).cast<float>();
}

HoleFrame MakeHoleFrame(const PointList& rim, const PointList& points, const std::vector<int>& support,
                        const Eigen::Vector3d& outward_hint) {
  constexpr geometry::EigenSolve kSolve = geometry::EigenSolve::kClosedForm;
  const auto rim_point = [&](size_t i) -> Eigen::Vector3d { return rim[i].cast<double>(); };
  geometry::PlaneFit plane = geometry::FitPlane(rim.size(), rim_point, kSolve);
  // A rim too thin to span a plane (a degenerate boundary): the support's.
  if (!(plane.eigenvalues(1) > 1e-4 * plane.eigenvalues(2))) {
    const auto support_point = [&](size_t i) -> Eigen::Vector3d { return points[support[i]].cast<double>(); };
    plane = geometry::FitPlane(support.size(), support_point, kSolve);
  }
  HoleFrame f;
  f.n = plane.normal;
  f.origin = plane.mean;
  if (f.n.dot(outward_hint) < 0.0) f.n = -f.n;
  Eigen::Vector3d e2 = Eigen::Vector3d::UnitZ() - f.n.z() * f.n;
  if (e2.norm() < 0.1) e2 = Eigen::Vector3d::UnitX() - f.n.x() * f.n;
  f.e2 = e2.normalized();
  f.e1 = f.e2.cross(f.n);
  return f;
}

HoleFrame FrameFromPlane(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3f& centroid) {
  const geometry::PlaneFit plane = geometry::FitPlane(
      pts.size(), [&](size_t i) -> const Eigen::Vector3d& { return pts[i]; },
      geometry::EigenSolve::kClosedForm);
  HoleFrame f;
  f.n = plane.normal;
  f.origin = plane.mean;
  if ((f.origin - centroid.cast<double>()).dot(f.n) < 0.0) f.n = -f.n;
  Eigen::Vector3d e2 = Eigen::Vector3d::UnitZ() - f.n.z() * f.n;
  if (e2.norm() < 0.1) e2 = Eigen::Vector3d::UnitX() - f.n.x() * f.n;
  f.e2 = e2.normalized();
  f.e1 = f.e2.cross(f.n);
  return f;
}

FillRegion RimRegion(const PointList& rim, const HoleFrame& f, double pad, double z_lo, double z_hi) {
  FillRegion r;
  r.lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  r.hi = -r.lo;
  for (const Eigen::Vector3f& p : rim) {
    const Eigen::Vector3d l = f.Local(p.cast<double>());
    r.lo = r.lo.cwiseMin(l);
    r.hi = r.hi.cwiseMax(l);
  }
  r.lo.head<2>().array() -= pad;
  r.hi.head<2>().array() += pad;
  r.z_lo = z_lo;
  r.z_hi = z_hi;
  return r;
}

}  // namespace graspfill::repair::fill
