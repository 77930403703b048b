// SPDX-License-Identifier: BSD-3-Clause
// The planner's mesh: the dense mesh decimated (Open3D's quadric
// decimation) or rebuilt coarser, inflated until it holds the cloud, and
// checked watertight by Open3D; or a convex hull (qhull through Open3D).
#include "graspfill/mesh/planner_mesh.hpp"

#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
#include <stdexcept>
#include <string>
#include <vector>

#include "graspfill/synth/mesh_sampling.hpp"

namespace graspfill::mesh {
namespace {

// Coarser cells for the fallback: triangles fall as 1 / cell^2; a little
// more than the ratio says, so that one or two tries reach the cap.
constexpr double kCoarsenMargin = 1.1;
constexpr int kMaxCoarsenTries = 6;
// A quadric mesh that is not good is decimated again to this fraction of
// its triangles, up to so many times.
constexpr double kRedecimationRatio = 0.85;
constexpr int kMaxRedecimations = 3;
// CollisionMeshConfig::Validate's largest cell [m].
constexpr double kMaxCellM = 0.02;

open3d::geometry::TriangleMesh ToOpen3d(const TriangleMesh& m) {
  open3d::geometry::TriangleMesh o;
  o.vertices_.reserve(m.vertices.size());
  for (const Eigen::Vector3f& v : m.vertices) o.vertices_.push_back(v.cast<double>());
  o.triangles_ = m.triangles;
  return o;
}

TriangleMesh FromOpen3d(const open3d::geometry::TriangleMesh& o) {
  TriangleMesh m;
  m.vertices.reserve(o.vertices_.size());
  for (const Eigen::Vector3d& v : o.vertices_) m.vertices.push_back(v.cast<float>());
  m.triangles = o.triangles_;
  return m;
}

// Triangles turned to face outwards (qhull's come either way).
void FaceOutwards(TriangleMesh* m) {
  if (synth::SignedVolume(*m) >= 0.0) return;
  for (Eigen::Vector3i& t : m->triangles) std::swap(t[1], t[2]);
}

TriangleMesh QuadricDecimation(const TriangleMesh& dense, int max_triangles) {
  const std::shared_ptr<open3d::geometry::TriangleMesh> o = ToOpen3d(dense).SimplifyQuadricDecimation(
      max_triangles, std::numeric_limits<double>::infinity(), 1.0);
  o->RemoveDegenerateTriangles();
  o->RemoveUnreferencedVertices();
  return FromOpen3d(*o);
}

// The convex hull of `points` with outward triangles; empty when qhull
// cannot make one (all points on a plane).
TriangleMesh ConvexHull(const std::vector<Eigen::Vector3f>& points) {
  open3d::geometry::PointCloud pc;
  pc.points_.reserve(points.size());
  for (const Eigen::Vector3f& p : points) pc.points_.push_back(p.cast<double>());
  TriangleMesh hull;
  try {
    hull = FromOpen3d(*std::get<0>(pc.ComputeConvexHull()));
  } catch (const std::exception&) {
    return {};  // qhull's error: a flat or degenerate set
  }
  FaceOutwards(&hull);
  return hull;
}

// A mesh as a candidate answer: inflated, then checked.
struct Candidate {
  TriangleMesh mesh;
  bool watertight{false};
  double inflation_max_m{0.0};
  int rounds{0};
  std::vector<double> outside_m;
};

Candidate Inflated(TriangleMesh mesh, const ObjectCloud& cloud, const PlannerMeshConfig& config) {
  Candidate c;
  c.mesh = std::move(mesh);
  if (c.mesh.empty() || !IsWatertight(c.mesh)) return c;
  c.rounds = InflateToContain(cloud.points_G, config.outside_tolerance_m,
                              config.max_inflation_rounds, &c.mesh, &c.inflation_max_m);
  c.watertight = IsWatertight(c.mesh);
  c.outside_m = OutsideDistances(c.mesh, cloud.points_G);
  return c;
}

// The grid's mesh `mesh` moved out through its field's level set
// (CollisionMeshConfig::offset_m: watertight by construction, where moving
// vertices can fold triangles over) until it holds the cloud, at most half
// the band out.
Candidate OffsetGrid(TriangleMesh mesh, const ObjectCloud& cloud, CollisionMeshConfig grid,
                     const PlannerMeshConfig& config) {
  Candidate c;
  c.mesh = std::move(mesh);
  const double most_m = 0.5 * grid.band_cells * grid.cell_m;
  for (int round = 0; !c.mesh.empty(); ++round) {
    c.outside_m = OutsideDistances(c.mesh, cloud.points_G);
    const double outside_m = SummarizeOutside(c.outside_m).max_m;
    if (outside_m <= config.outside_tolerance_m || grid.offset_m >= most_m ||
        round == config.max_inflation_rounds) {
      break;
    }
    grid.offset_m = std::min(most_m, grid.offset_m + outside_m);
    c.mesh = BuildCollisionMesh(cloud, grid);
    c.rounds = round + 1;
    c.inflation_max_m = grid.offset_m;
  }
  c.watertight = !c.mesh.empty() && IsWatertight(c.mesh);
  return c;
}

// Fits the cap and the tolerance (a watertight mesh with its points held).
bool Good(const Candidate& c, const PlannerMeshConfig& config) {
  return c.watertight && static_cast<int64_t>(c.mesh.triangles.size()) <= config.max_triangles &&
         SummarizeOutside(c.outside_m).max_m <= config.outside_tolerance_m;
}

// Why a candidate is not good, for fallback_reason.
std::string Defect(const Candidate& c, const PlannerMeshConfig& config) {
  if (c.mesh.empty()) return "no mesh";
  if (c.outside_m.empty()) return "not watertight before inflation";
  if (!c.watertight) return "not watertight after inflation";
  if (static_cast<int64_t>(c.mesh.triangles.size()) > config.max_triangles) {
    return std::to_string(c.mesh.triangles.size()) + " triangles";
  }
  return "points " + std::to_string(SummarizeOutside(c.outside_m).max_m * 1e3) +
         " mm outside after " + std::to_string(c.rounds) + " rounds";
}

PlannerMesh Finish(Candidate c, CollisionMeshKind kind, PlannerMeshMethod method) {
  PlannerMesh p;
  p.kind = kind;
  p.method = method;
  p.watertight = c.watertight;
  p.outside = SummarizeOutside(c.outside_m);
  p.inflation_max_m = c.inflation_max_m;
  p.inflation_rounds = c.rounds;
  p.mesh = std::move(c.mesh);
  return p;
}

// The hull, measured (it holds every point by construction, up to float
// rounding, which OutsideDistances sees).
Candidate Hull(const std::vector<Eigen::Vector3f>& points) {
  Candidate c;
  c.mesh = ConvexHull(points);
  if (c.mesh.empty()) return c;
  c.watertight = IsWatertight(c.mesh);
  return c;
}

// The hull of `points`, within the cap, measured against the cloud.
PlannerMesh HullOf(const std::vector<Eigen::Vector3f>& points, const ObjectCloud& cloud,
                   const PlannerMeshConfig& config) {
  Candidate c = Hull(points);
  if (c.mesh.empty()) {
    throw std::runtime_error("planner mesh: no convex hull of the cloud (are its points on a plane?)");
  }
  if (static_cast<int64_t>(c.mesh.triangles.size()) > config.max_triangles) {
    throw std::runtime_error("planner mesh: the convex hull has " +
                             std::to_string(c.mesh.triangles.size()) + " triangles, over the cap of " +
                             std::to_string(config.max_triangles));
  }
  c.outside_m = OutsideDistances(c.mesh, cloud.points_G);
  return Finish(std::move(c), CollisionMeshKind::kConvexHull, PlannerMeshMethod::kConvexHull);
}

// The decimated shape (kDecimated), or the cloud's hull where no decimated
// mesh is good (fallback_reason says why).
PlannerMesh BuildDecimated(const ObjectCloud& cloud, const PlannerMeshConfig& config) {
  const TriangleMesh dense = BuildCollisionMesh(cloud, config.dense);
  const int64_t dense_triangles = static_cast<int64_t>(dense.triangles.size());
  const bool fits = dense_triangles <= config.max_triangles;
  Candidate decimated;
  if (fits) {
    decimated = Inflated(dense, cloud, config);
  } else {
    // Quadric decimation now and then leaves a non-manifold edge or a
    // self-intersection: decimating its result a little further clears it.
    TriangleMesh m = QuadricDecimation(dense, config.max_triangles);
    for (int attempt = 0; attempt <= kMaxRedecimations; ++attempt) {
      decimated = Inflated(m, cloud, config);
      if (Good(decimated, config) || attempt == kMaxRedecimations) break;
      m = QuadricDecimation(m, static_cast<int>(kRedecimationRatio * m.triangles.size()));
    }
  }
  PlannerMesh result;
  if (Good(decimated, config)) {
    result = Finish(std::move(decimated), CollisionMeshKind::kDecimated,
                    fits ? PlannerMeshMethod::kDense : PlannerMeshMethod::kQuadric);
  } else {
    std::string reason = std::string(fits ? "dense" : "quadric") + ": " + Defect(decimated, config);
    // Coarser cells until the mesh fits the cap (watertight by construction).
    CollisionMeshConfig coarse = config.dense;
    int64_t triangles = dense_triangles;
    Candidate c;
    std::optional<std::pair<TriangleMesh, CollisionMeshConfig>> first_fit;
    for (int attempt = 0; attempt < kMaxCoarsenTries && coarse.cell_m < kMaxCellM; ++attempt) {
      const double ratio = std::max(1.0, static_cast<double>(triangles) / config.max_triangles);
      coarse.cell_m = std::min(kMaxCellM, coarse.cell_m * std::sqrt(ratio) * kCoarsenMargin);
      const TriangleMesh m = BuildCollisionMesh(cloud, coarse);
      triangles = static_cast<int64_t>(m.triangles.size());
      if (triangles > config.max_triangles) continue;
      // Inflated as the quadric mesh is (tighter: it moves only where
      // points are outside); the first that fits kept for the level set.
      if (!first_fit) first_fit.emplace(m, coarse);
      c = Inflated(m, cloud, config);
      if (Good(c, config)) break;
    }
    if (!Good(c, config) && first_fit) {
      c = OffsetGrid(first_fit->first, cloud, first_fit->second, config);
    }
    if (Good(c, config)) {
      result = Finish(std::move(c), CollisionMeshKind::kDecimated, PlannerMeshMethod::kCoarseGrid);
    } else {
      reason += "; coarse grid: " + Defect(c, config);
      result = HullOf(cloud.points_G, cloud, config);
    }
    result.fallback_reason = reason;
  }
  result.dense_triangles = dense_triangles;
  return result;
}

}  // namespace

const char* PlannerMeshMethodName(PlannerMeshMethod method) {
  switch (method) {
    case PlannerMeshMethod::kDense: return "dense";
    case PlannerMeshMethod::kQuadric: return "quadric";
    case PlannerMeshMethod::kCoarseGrid: return "coarse_grid";
    case PlannerMeshMethod::kConvexHull: return "convex_hull";
  }
  return "unknown";
}

void PlannerMeshConfig::Validate() const {
  auto check = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("PlannerMeshConfig: " + what);
  };
  check(max_triangles >= kMinPlannerTriangles && max_triangles <= kMaxPlannerTriangles,
        "max_triangles must be in " + std::to_string(kMinPlannerTriangles) + ".." +
            std::to_string(kMaxPlannerTriangles) + ", not " + std::to_string(max_triangles));
  check(std::isfinite(outside_tolerance_m) && outside_tolerance_m >= 0.0 && outside_tolerance_m <= 0.01,
        "outside_tolerance_m must be in 0..0.01 m, not " + std::to_string(outside_tolerance_m));
  check(max_inflation_rounds >= 1 && max_inflation_rounds <= 50,
        "max_inflation_rounds must be in 1..50, not " + std::to_string(max_inflation_rounds));
  dense.Validate();
}

bool IsWatertight(const TriangleMesh& mesh) { return ToOpen3d(mesh).IsWatertight(); }

int InflateToContain(const std::vector<Eigen::Vector3f>& points, double tolerance_m,
                     int max_rounds, TriangleMesh* mesh, double* moved_max_m) {
  std::vector<double> moved(mesh->vertices.size(), 0.0);
  std::vector<int> closest;
  std::vector<double> push(mesh->vertices.size());
  int round = 0;
  for (; round < max_rounds; ++round) {
    const std::vector<double> outside = OutsideDistances(*mesh, points, &closest);
    if (SummarizeOutside(outside).max_m <= tolerance_m) break;
    // Each vertex by the farthest point outside near it: the points whose
    // closest triangle has it.
    std::fill(push.begin(), push.end(), 0.0);
    for (size_t i = 0; i < points.size(); ++i) {
      if (outside[i] <= 0.0) continue;
      for (int k = 0; k < 3; ++k) {
        double& p = push[static_cast<size_t>(mesh->triangles[static_cast<size_t>(closest[i])][k])];
        p = std::max(p, outside[i]);
      }
    }
    open3d::geometry::TriangleMesh o = ToOpen3d(*mesh);
    o.ComputeVertexNormals();
    for (size_t v = 0; v < mesh->vertices.size(); ++v) {
      if (push[v] <= 0.0) continue;
      mesh->vertices[v] += (push[v] * o.vertex_normals_[v]).cast<float>();
      moved[v] += push[v];
    }
  }
  *moved_max_m = moved.empty() ? 0.0 : *std::max_element(moved.begin(), moved.end());
  return round;
}

PlannerMesh BuildPlannerMesh(const ObjectCloud& cloud, const PlannerMeshConfig& config) {
  config.Validate();
  if (!config.convex_hull) return BuildDecimated(cloud, config);
  if (cloud.size() < 4) {
    throw std::invalid_argument("planner mesh: the cloud has " + std::to_string(cloud.size()) +
                                " points; at least 4 are needed");
  }
  if (static_cast<int64_t>(ConvexHull(cloud.points_G).triangles.size()) <= config.max_triangles) {
    return HullOf(cloud.points_G, cloud, config);
  }
  // Too many for the cap: the hull of the decimated mesh's vertices.
  const PlannerMesh shape = BuildDecimated(cloud, config);
  PlannerMesh hull = HullOf(shape.mesh.vertices, cloud, config);
  hull.dense_triangles = shape.dense_triangles;
  hull.fallback_reason = "the cloud's hull is over the cap: the hull of the decimated mesh";
  return hull;
}

}  // namespace graspfill::mesh
