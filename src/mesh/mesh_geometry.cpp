// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/mesh/mesh_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "graspfill/core/random.hpp"

namespace graspfill::mesh {
namespace {

Eigen::Vector3d Vertex(const TriangleMesh& mesh, int i) { return mesh.vertices[i].cast<double>(); }

}  // namespace

SurfaceSamples SampleSurface(const TriangleMesh& mesh, int count, uint64_t seed) {
  SurfaceSamples out;
  if (count <= 0 || mesh.triangles.empty()) return out;
  // Cumulative areas: a uniform draw on [0, total) picks a triangle with
  // probability proportional to its area.
  std::vector<double> cumulative(mesh.triangles.size());
  double total = 0.0;
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const Eigen::Vector3i& t = mesh.triangles[i];
    const Eigen::Vector3d a = Vertex(mesh, t[0]);
    total += 0.5 * (Vertex(mesh, t[1]) - a).cross(Vertex(mesh, t[2]) - a).norm();
    cumulative[i] = total;
  }
  if (!(total > 0.0)) return out;
  Rng rng(seed);
  out.points.reserve(count);
  out.normals.reserve(count);
  for (int k = 0; k < count; ++k) {
    const double r = rng.Uniform() * total;
    const size_t i =
        std::min<size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), r) - cumulative.begin(),
                         cumulative.size() - 1);
    const Eigen::Vector3i& t = mesh.triangles[i];
    const Eigen::Vector3d a = Vertex(mesh, t[0]);
    const Eigen::Vector3d b = Vertex(mesh, t[1]);
    const Eigen::Vector3d c = Vertex(mesh, t[2]);
    // Uniform on the triangle: fold the unit square onto it via sqrt.
    const double s = std::sqrt(rng.Uniform());
    const double u = rng.Uniform();
    const Eigen::Vector3d p = (1.0 - s) * a + s * (1.0 - u) * b + s * u * c;
    Eigen::Vector3d n = (b - a).cross(c - a);
    const double norm = n.norm();
    n = norm > 0.0 ? Eigen::Vector3d(n / norm) : Eigen::Vector3d::UnitZ();
    out.points.push_back(p.cast<float>());
    out.normals.push_back(n.cast<float>());
  }
  return out;
}

double SurfaceArea(const TriangleMesh& mesh) {
  double area = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = Vertex(mesh, t[0]);
    area += 0.5 * (Vertex(mesh, t[1]) - a).cross(Vertex(mesh, t[2]) - a).norm();
  }
  return area;
}

double SignedVolume(const TriangleMesh& mesh) {
  double six_volume = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    six_volume += Vertex(mesh, t[0]).dot(Vertex(mesh, t[1]).cross(Vertex(mesh, t[2])));
  }
  return six_volume / 6.0;
}

bool IsClosedOriented(const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) return false;
  std::map<std::pair<int, int>, int> directed;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  }
  for (const auto& [edge, uses] : directed) {
    if (uses != 1) return false;
    const auto reverse = directed.find({edge.second, edge.first});
    if (reverse == directed.end() || reverse->second != 1) return false;
  }
  return true;
}

Eigen::AlignedBox3d Bounds(const TriangleMesh& mesh) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3f& v : mesh.vertices) box.extend(v.cast<double>());
  return box;
}

double WindingNumber(const TriangleMesh& mesh, const Eigen::Vector3d& p) {
  // Van Oosterom and Strackee's solid angle of each triangle seen from p.
  double sum = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>() - p;
    const Eigen::Vector3d b = mesh.vertices[t[1]].cast<double>() - p;
    const Eigen::Vector3d c = mesh.vertices[t[2]].cast<double>() - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    sum += 2.0 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return sum / (4.0 * 3.14159265358979323846);
}

double PointTriangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                             const Eigen::Vector3d& c) {
  // Closest point by Voronoi regions (Ericson, Real-Time Collision
  // Detection, 5.1.5).
  const Eigen::Vector3d ab = b - a;
  const Eigen::Vector3d ac = c - a;
  const Eigen::Vector3d ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return ap.norm();
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return bp.norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    return (p - (a + d1 / (d1 - d3) * ab)).norm();
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return cp.norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    return (p - (a + d2 / (d2 - d6) * ac)).norm();
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
  }
  const double denom = 1.0 / (va + vb + vc);
  return (p - (a + ab * (vb * denom) + ac * (vc * denom))).norm();
}

}  // namespace graspfill::mesh
