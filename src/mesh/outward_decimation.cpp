// SPDX-License-Identifier: BSD-3-Clause
#include "outward_decimation.hpp"

#include <open3d/geometry/IntersectionTest.h>
#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <queue>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "triangle_grid.hpp"

namespace graspfill::mesh {
namespace {

using Vec3 = Eigen::Vector3d;
using Quadric = Eigen::Matrix4d;

// A new vertex may sit this far inside an old triangle's plane [m]: the
// rounding of float vertices (1e-8 m at a metre), not a tolerance on
// shape.
constexpr double kPlaneSlackM = 1e-9;
// A triangle whose doubled area falls below this [m^2] counts as
// degenerate: 1 um x 1 um.
constexpr double kMinDoubleAreaM2 = 1e-12;
// Eigenvalues of the quadric's 3x3 part below this fraction of the
// largest are treated as zero (flat or straight neighbourhoods leave the
// optimum free along them; it is then taken nearest the edge's midpoint).
constexpr double kQuadricRankTolerance = 1e-6;
// Planes whose normals' Gram determinant falls below this meet too far
// off (at 1e-6, two planes 0.06 degrees apart) to place a vertex.
constexpr double kMinPlaneGramDeterminant = 1e-6;
// The triangle grid's smallest cell [m]: 0.5 mm keeps a fine mesh from
// making millions of cells.
constexpr double kMinGridCellM = 0.0005;

struct Plane {
  Vec3 normal;    // unit, outwards
  double offset;  // normal . x for points x on the plane
};

// Moves *v to the point of the active planes' intersection nearest to it,
// v + N^T (N N^T)^-1 (d - N v); false where the planes are (nearly)
// parallel and their intersection runs off.
template <int kRows>
bool ProjectOntoPlanes(const std::array<const Plane*, 3>& active, Vec3* v) {
  Eigen::Matrix<double, kRows, 3> N;
  Eigen::Matrix<double, kRows, 1> d;
  for (int k = 0; k < kRows; ++k) {
    N.row(k) = active[k]->normal.transpose();
    d[k] = active[k]->offset;
  }
  const Eigen::Matrix<double, kRows, kRows> gram = N * N.transpose();
  if (std::abs(gram.determinant()) < kMinPlaneGramDeterminant) return false;
  *v += N.transpose() * gram.inverse() * (d - N * *v);
  return true;
}

bool ProjectOntoPlanes(const std::array<const Plane*, 3>& active, int num_active, Vec3* v) {
  switch (num_active) {
    case 1:
      return ProjectOntoPlanes<1>(active, v);
    case 2:
      return ProjectOntoPlanes<2>(active, v);
    default:
      return ProjectOntoPlanes<3>(active, v);
  }
}

struct Candidate {
  double cost;
  int a;
  int b;
  uint32_t stamp_a;
  uint32_t stamp_b;
  Vec3 position;
};

struct CheaperFirst {
  bool operator()(const Candidate& x, const Candidate& y) const {
    if (x.cost != y.cost) return x.cost > y.cost;
    if (x.a != y.a) return x.a > y.a;  // ties: by index, for determinism
    return x.b > y.b;
  }
};

class Decimator {
 public:
  Decimator(const TriangleMesh& mesh, int max_triangles);

  OutwardDecimation Run();

 private:
  Plane FitPlane(int face) const;
  Vec3 Normal2(int face) const;  // cross product: twice the area, outwards
  // The vertices adjacent to v.
  void Neighbors(int v, std::vector<int>* out) const;
  bool LinkConditionHolds(int a, int b);
  // The feasible position for collapsing (a, b) and its cost; false if
  // none is allowed.
  bool Evaluate(int a, int b, Vec3* position, double* cost);
  // Moves *v onto the outer side of every plane in planes_; false if three
  // projections do not get it there.
  bool MakeFeasible(Vec3* v) const;
  // No triangle around the collapse of (a, b) to v turns over or vanishes.
  bool KeepsTrianglesUpright(int a, int b, const Vec3& v) const;
  // Whether the fan that collapsing (a, b) to `v` makes would cut through
  // a triangle outside it (two sheets of a thin wall growing into each
  // other).
  bool CrossesAnotherTriangle(int a, int b, const Vec3& v);
  Eigen::AlignedBox3d BoxOf(int face) const;
  void PushEdgesOf(int v);
  void Collapse(int a, int b, const Vec3& position);
  OutwardDecimation Compact(int collapses, bool reached_budget) const;

  std::vector<Vec3> positions_;
  std::vector<Quadric> quadrics_;
  std::vector<uint32_t> stamps_;
  std::vector<std::array<int, 3>> faces_;
  std::vector<bool> face_alive_;
  std::vector<std::vector<int>> vertex_faces_;  // live faces around each vertex
  int live_faces_{0};
  int max_triangles_;
  std::optional<TriangleGrid> grid_;
  std::priority_queue<Candidate, std::vector<Candidate>, CheaperFirst> heap_;
  // Scratch reused across collapses.
  std::vector<int> scratch_a_;
  std::vector<Plane> planes_of_faces_;  // kept current as vertices move
  std::vector<uint32_t> marks_;         // per vertex, for the link condition
  uint32_t mark_stamp_{0};
  std::vector<Plane> planes_;
  std::vector<int> near_;
};

// Checks that every directed edge appears once and its reverse once.
void RequireClosedManifold(const TriangleMesh& mesh) {
  const int n = static_cast<int>(mesh.vertices.size());
  std::unordered_map<uint64_t, int> directed;
  directed.reserve(mesh.triangles.size() * 3);
  auto key = [](int from, int to) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(from)) << 32) | static_cast<uint32_t>(to);
  };
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      if (t[k] < 0 || t[k] >= n) {
        throw std::invalid_argument("DecimateOutward: a triangle indexes vertex " + std::to_string(t[k]) +
                                    " of " + std::to_string(n));
      }
    }
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      throw std::invalid_argument("DecimateOutward: a triangle repeats a vertex");
    }
    for (int k = 0; k < 3; ++k) {
      if (++directed[key(t[k], t[(k + 1) % 3])] > 1) {
        throw std::invalid_argument("DecimateOutward: the mesh is not a consistently oriented 2-manifold");
      }
    }
  }
  for (const auto& [edge, count] : directed) {
    const int from = static_cast<int>(edge >> 32);
    const int to = static_cast<int>(edge & 0xffffffffu);
    if (directed.count(key(to, from)) == 0) {
      throw std::invalid_argument("DecimateOutward: the mesh is not closed (an edge has one triangle)");
    }
  }
}

Decimator::Decimator(const TriangleMesh& mesh, int max_triangles)
    : positions_(mesh.vertices.size()),
      quadrics_(mesh.vertices.size(), Quadric::Zero()),
      stamps_(mesh.vertices.size(), 0),
      faces_(mesh.triangles.size()),
      face_alive_(mesh.triangles.size(), true),
      vertex_faces_(mesh.vertices.size()),
      live_faces_(static_cast<int>(mesh.triangles.size())),
      max_triangles_(max_triangles),
      marks_(mesh.vertices.size(), 0) {
  for (size_t i = 0; i < mesh.vertices.size(); ++i) positions_[i] = mesh.vertices[i].cast<double>();
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const Eigen::Vector3i& t = mesh.triangles[f];
    faces_[f] = {t[0], t[1], t[2]};
    for (int k = 0; k < 3; ++k) vertex_faces_[t[k]].push_back(static_cast<int>(f));
  }
  planes_of_faces_.resize(faces_.size());
  for (size_t f = 0; f < faces_.size(); ++f) planes_of_faces_[f] = FitPlane(static_cast<int>(f));
  // Garland-Heckbert: each vertex starts with its triangles' planes,
  // weighted by area so that the metric does not depend on the tessellation.
  for (size_t f = 0; f < faces_.size(); ++f) {
    const Vec3 n2 = Normal2(static_cast<int>(f));
    const double double_area = n2.norm();
    if (double_area < kMinDoubleAreaM2) continue;
    const Plane& plane = planes_of_faces_[f];
    Eigen::Vector4d p(plane.normal.x(), plane.normal.y(), plane.normal.z(), -plane.offset);
    const Quadric q = 0.5 * double_area * (p * p.transpose());
    for (int k = 0; k < 3; ++k) quadrics_[faces_[f][k]] += q;
  }
  // Cells between the size the triangles have and the size they will have
  // at the budget (their geometric mean), so that neither the first fans'
  // queries nor the last triangles' filing meet many cells.
  double area_m2 = 0.0;
  for (size_t f = 0; f < faces_.size(); ++f) area_m2 += 0.5 * Normal2(static_cast<int>(f)).norm();
  auto edge_m = [&](double triangles) { return std::sqrt(4.0 * area_m2 / (std::sqrt(3.0) * triangles)); };
  const double cell_m = std::sqrt(edge_m(static_cast<double>(faces_.size())) * edge_m(max_triangles));
  grid_.emplace(static_cast<int>(faces_.size()), std::max(cell_m, kMinGridCellM));
  for (size_t f = 0; f < faces_.size(); ++f) grid_->Place(static_cast<int>(f), BoxOf(static_cast<int>(f)));
}

Eigen::AlignedBox3d Decimator::BoxOf(int face) const {
  Eigen::AlignedBox3d box;
  for (int v : faces_[face]) box.extend(positions_[v]);
  return box;
}

bool Decimator::CrossesAnotherTriangle(int a, int b, const Vec3& v) {
  auto corner = [&](int u) -> Vec3 { return (u == a || u == b) ? v : positions_[u]; };
  auto merged = [&](int u) { return u == b ? a : u; };
  for (int end : {a, b}) {
    for (int f : vertex_faces_[end]) {
      const auto& t = faces_[f];
      const bool has_a = t[0] == a || t[1] == a || t[2] == a;
      const bool has_b = t[0] == b || t[1] == b || t[2] == b;
      if ((has_a && has_b) || (end == b && has_a)) continue;
      const Vec3 p0 = corner(t[0]), p1 = corner(t[1]), p2 = corner(t[2]);
      Eigen::AlignedBox3d box(p0);
      box.extend(p1);
      box.extend(p2);
      grid_->Near(box, &near_);
      for (int g : near_) {
        const auto& u = faces_[g];
        // Triangles with a corner in common touch there by design.
        bool shares = false;
        for (int i = 0; i < 3 && !shares; ++i) {
          for (int j = 0; j < 3 && !shares; ++j) shares = merged(t[i]) == merged(u[j]);
        }
        if (shares) continue;
        if (open3d::geometry::IntersectionTest::TriangleTriangle3d(p0, p1, p2, corner(u[0]), corner(u[1]),
                                                                   corner(u[2]))) {
          return true;
        }
      }
    }
  }
  return false;
}

Vec3 Decimator::Normal2(int face) const {
  const auto& t = faces_[face];
  return (positions_[t[1]] - positions_[t[0]]).cross(positions_[t[2]] - positions_[t[0]]);
}

Plane Decimator::FitPlane(int face) const {
  const Vec3 n2 = Normal2(face);
  const double norm = n2.norm();
  const Vec3 normal = norm > 0.0 ? Vec3(n2 / norm) : Vec3::Zero();
  return {normal, normal.dot(positions_[faces_[face][0]])};
}

void Decimator::Neighbors(int v, std::vector<int>* out) const {
  out->clear();
  for (int f : vertex_faces_[v]) {
    for (int u : faces_[f]) {
      if (u != v) out->push_back(u);
    }
  }
  std::sort(out->begin(), out->end());
  out->erase(std::unique(out->begin(), out->end()), out->end());
}

bool Decimator::LinkConditionHolds(int a, int b) {
  if (++mark_stamp_ == 0) {  // wrapped: forget every old mark
    std::fill(marks_.begin(), marks_.end(), 0);
    mark_stamp_ = 1;
  }
  for (int f : vertex_faces_[a]) {
    for (int u : faces_[f]) marks_[u] = mark_stamp_;
  }
  int shared = 0;
  for (int f : vertex_faces_[b]) {
    for (int u : faces_[f]) {
      if (u == a || u == b || marks_[u] != mark_stamp_) continue;
      marks_[u] = 0;  // counted once
      ++shared;
    }
  }
  return shared == 2;
}

bool Decimator::MakeFeasible(Vec3* v) const {
  // Project onto the most violated plane, then onto the line two violated
  // planes share, then their point with a third.
  std::array<const Plane*, 3> active{};
  int num_active = 0;
  for (;;) {
    const Plane* worst = nullptr;
    double worst_violation = kPlaneSlackM;
    for (const Plane& p : planes_) {
      const double violation = p.offset - p.normal.dot(*v);
      if (violation > worst_violation) {
        worst_violation = violation;
        worst = &p;
      }
    }
    if (worst == nullptr) return true;
    if (num_active == 3) return false;
    active[num_active++] = worst;
    if (!ProjectOntoPlanes(active, num_active, v)) return false;
    // Lift it by the slack so that rounding does not leave it inside.
    for (int k = 0; k < num_active; ++k) *v += active[k]->normal * (kPlaneSlackM / num_active);
  }
}

bool Decimator::KeepsTrianglesUpright(int a, int b, const Vec3& v) const {
  for (int end : {a, b}) {
    for (int f : vertex_faces_[end]) {
      const auto& t = faces_[f];
      const bool has_a = t[0] == a || t[1] == a || t[2] == a;
      const bool has_b = t[0] == b || t[1] == b || t[2] == b;
      if (has_a && has_b) continue;  // removed by the collapse
      if (end == b && has_a) continue;
      std::array<Vec3, 3> corners;
      for (int k = 0; k < 3; ++k) corners[k] = (t[k] == a || t[k] == b) ? v : positions_[t[k]];
      const Vec3 after = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
      if (after.norm() < kMinDoubleAreaM2) return false;
      if (after.dot(planes_of_faces_[f].normal) <= 0.0) return false;
    }
  }
  return true;
}

bool Decimator::Evaluate(int a, int b, Vec3* position, double* cost) {
  if (!LinkConditionHolds(a, b)) return false;
  const Quadric q = quadrics_[a] + quadrics_[b];
  const Eigen::Matrix3d A = q.topLeftCorner<3, 3>();
  const Vec3 rhs = -q.topRightCorner<3, 1>();
  // The quadric's optimum, taken nearest the midpoint along directions it
  // leaves free.
  const Vec3 mid = 0.5 * (positions_[a] + positions_[b]);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(A);
  const Vec3 residual = eig.eigenvectors().transpose() * (rhs - A * mid);
  const double largest = eig.eigenvalues().cwiseAbs().maxCoeff();
  Vec3 step = Vec3::Zero();
  for (int k = 0; k < 3; ++k) {
    const double lambda = eig.eigenvalues()[k];
    if (largest > 0.0 && std::abs(lambda) > kQuadricRankTolerance * largest) step[k] = residual[k] / lambda;
  }

  // Every plane around a and b, as constraints n . v >= offset.
  planes_.clear();
  for (int end : {a, b}) {
    for (int f : vertex_faces_[end]) {
      if (end == b && (faces_[f][0] == a || faces_[f][1] == a || faces_[f][2] == a)) continue;
      const Plane& p = planes_of_faces_[f];
      if (p.normal.squaredNorm() > 0.0) planes_.push_back(p);
    }
  }
  // The quadric's optimum moved onto the feasible side, or either end
  // (on a bumpy surface the higher end often is already outside every
  // plane, where the optimum would be pushed out past the bumps): the
  // feasible one the quadric prefers.
  bool found = false;
  for (Vec3 v : {Vec3(mid + eig.eigenvectors() * step), positions_[a], positions_[b]}) {
    if (!MakeFeasible(&v) || !KeepsTrianglesUpright(a, b, v)) continue;
    const Eigen::Vector4d h(v.x(), v.y(), v.z(), 1.0);
    const double c = h.dot(q * h);
    if (!found || c < *cost) {
      *position = v;
      *cost = c;
      found = true;
    }
  }
  return found;
}

void Decimator::PushEdgesOf(int v) {
  std::vector<int> neighbors;
  Neighbors(v, &neighbors);
  for (int u : neighbors) {
    const int a = std::min(u, v);
    const int b = std::max(u, v);
    Vec3 position;
    double cost = 0.0;
    if (Evaluate(a, b, &position, &cost)) heap_.push({cost, a, b, stamps_[a], stamps_[b], position});
  }
}

void Decimator::Collapse(int a, int b, const Vec3& position) {
  // The two triangles on the edge go; b's others take a in its place.
  for (int f : vertex_faces_[b]) {
    auto& t = faces_[f];
    if (t[0] == a || t[1] == a || t[2] == a) {
      face_alive_[f] = false;
      grid_->Remove(f);
      --live_faces_;
      for (int u : t) {
        if (u == b) continue;
        auto& list = vertex_faces_[u];
        list.erase(std::remove(list.begin(), list.end(), f), list.end());
      }
    } else {
      for (int& u : t) {
        if (u == b) u = a;
      }
      vertex_faces_[a].push_back(f);
    }
  }
  vertex_faces_[b].clear();
  positions_[a] = position;
  quadrics_[a] += quadrics_[b];
  for (int f : vertex_faces_[a]) {
    grid_->Place(f, BoxOf(f));
    planes_of_faces_[f] = FitPlane(f);
  }
  // Every edge whose neighbourhood changed is stale: a's and its neighbours'.
  ++stamps_[a];
  ++stamps_[b];
  Neighbors(a, &scratch_a_);
  for (int u : scratch_a_) ++stamps_[u];
}

OutwardDecimation Decimator::Run() {
  std::vector<int> neighbors;
  for (int v = 0; v < static_cast<int>(positions_.size()); ++v) {
    Neighbors(v, &neighbors);
    for (int u : neighbors) {
      if (u <= v) continue;
      Vec3 position;
      double cost = 0.0;
      if (Evaluate(v, u, &position, &cost)) heap_.push({cost, v, u, stamps_[v], stamps_[u], position});
    }
  }
  int collapses = 0;
  while (live_faces_ > max_triangles_ && !heap_.empty()) {
    const Candidate c = heap_.top();
    heap_.pop();
    if (vertex_faces_[c.a].empty() || vertex_faces_[c.b].empty()) continue;  // a vertex is gone
    if (c.stamp_a != stamps_[c.a] || c.stamp_b != stamps_[c.b]) {
      // Its neighbourhood changed since it was scored: score it again.
      Vec3 position;
      double cost = 0.0;
      if (Evaluate(c.a, c.b, &position, &cost)) {
        heap_.push({cost, c.a, c.b, stamps_[c.a], stamps_[c.b], position});
      }
      continue;
    }
    // A closed mesh needs at least a tetrahedron's four triangles.
    if (live_faces_ - 2 < 4) break;
    if (CrossesAnotherTriangle(c.a, c.b, c.position)) continue;
    Collapse(c.a, c.b, c.position);
    ++collapses;
    PushEdgesOf(c.a);
  }
  return Compact(collapses, live_faces_ <= max_triangles_);
}

OutwardDecimation Decimator::Compact(int collapses, bool reached_budget) const {
  OutwardDecimation out;
  out.collapses = collapses;
  out.reached_budget = reached_budget;
  std::vector<int> index(positions_.size(), -1);
  for (size_t f = 0; f < faces_.size(); ++f) {
    if (!face_alive_[f]) continue;
    Eigen::Vector3i t;
    for (int k = 0; k < 3; ++k) {
      const int v = faces_[f][k];
      if (index[v] < 0) {
        index[v] = static_cast<int>(out.mesh.vertices.size());
        out.mesh.vertices.push_back(positions_[v].cast<float>());
      }
      t[k] = index[v];
    }
    out.mesh.triangles.push_back(t);
  }
  return out;
}

}  // namespace

OutwardDecimation DecimateOutward(const TriangleMesh& closed_mesh, int max_triangles) {
  if (max_triangles < 4) {
    throw std::invalid_argument("DecimateOutward: max_triangles " + std::to_string(max_triangles) +
                                " is under a tetrahedron's 4");
  }
  RequireClosedManifold(closed_mesh);
  Decimator decimator(closed_mesh, max_triangles);
  return decimator.Run();
}

}  // namespace graspfill::mesh
