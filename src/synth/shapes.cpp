// SPDX-License-Identifier: BSD-3-Clause
#include "synth/shapes.hpp"

#include <cmath>
#include <stdexcept>

#include "graspfill/mesh/mesh_geometry.hpp"
#include "synth/internal/zoo_shapes.hpp"

namespace graspfill::synth {
namespace {

Eigen::Vector3f V(double x, double y, double z) {
  return Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
}

// Extrudes a convex polygon (counter-clockwise seen from +z) from z = 0 to
// z = height. Caps are fans around the polygon's vertex mean, which shares
// no edge with the sides, so the result is closed and outward-facing.
TriangleMesh ExtrudeConvexPolygon(const std::vector<Eigen::Vector2d>& polygon, double height) {
  TriangleMesh mesh;
  const int n = static_cast<int>(polygon.size());
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : polygon) centre += p;
  centre /= n;
  for (const Eigen::Vector2d& p : polygon) mesh.vertices.push_back(V(p.x(), p.y(), 0.0));
  for (const Eigen::Vector2d& p : polygon) mesh.vertices.push_back(V(p.x(), p.y(), height));
  const int c_bottom = 2 * n;
  const int c_top = 2 * n + 1;
  mesh.vertices.push_back(V(centre.x(), centre.y(), 0.0));
  mesh.vertices.push_back(V(centre.x(), centre.y(), height));
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    mesh.triangles.emplace_back(c_bottom, j, i);       // normal -z
    mesh.triangles.emplace_back(c_top, n + i, n + j);  // normal +z
    mesh.triangles.emplace_back(i, j, n + j);          // side, outward
    mesh.triangles.emplace_back(i, n + j, n + i);
  }
  return mesh;
}

std::vector<Eigen::Vector2d> Ellipse(double a, double b, int segments) {
  std::vector<Eigen::Vector2d> polygon;
  polygon.reserve(segments);
  for (int i = 0; i < segments; ++i) {
    const double phi = 2.0 * M_PI * i / segments;
    polygon.emplace_back(a * std::cos(phi), b * std::sin(phi));
  }
  return polygon;
}

// Latitude-longitude ellipsoid with single pole vertices (no degenerate
// triangles), centred at (0, 0, c) so that it spans z in [0, 2c].
TriangleMesh MakeEllipsoid(double a, double b, double c, int segments) {
  const int lon = segments;
  const int lat = segments / 2;  // rings from pole to pole
  TriangleMesh mesh;
  mesh.vertices.push_back(V(0.0, 0.0, 0.0));      // south pole: 0
  mesh.vertices.push_back(V(0.0, 0.0, 2.0 * c));  // north pole: 1
  // Ring k (1..lat-1) at polar angle theta_k from the south pole.
  for (int k = 1; k < lat; ++k) {
    const double theta = M_PI * k / lat;
    const double s = std::sin(theta);
    const double z = c - c * std::cos(theta);
    for (int i = 0; i < lon; ++i) {
      const double phi = 2.0 * M_PI * i / lon;
      mesh.vertices.push_back(V(a * s * std::cos(phi), b * s * std::sin(phi), z));
    }
  }
  auto ring = [lon](int k, int i) { return 2 + (k - 1) * lon + (i % lon); };
  for (int i = 0; i < lon; ++i) {
    mesh.triangles.emplace_back(0, ring(1, i + 1), ring(1, i));
    mesh.triangles.emplace_back(1, ring(lat - 1, i), ring(lat - 1, i + 1));
  }
  for (int k = 1; k + 1 < lat; ++k) {
    for (int i = 0; i < lon; ++i) {
      mesh.triangles.emplace_back(ring(k, i), ring(k, i + 1), ring(k + 1, i + 1));
      mesh.triangles.emplace_back(ring(k, i), ring(k + 1, i + 1), ring(k + 1, i));
    }
  }
  return mesh;
}

}  // namespace

const std::vector<Shape>& AllShapes() {
  static const std::vector<Shape> kAll = {Shape::kCuboid, Shape::kTriangularPrism,  Shape::kCylinder,
                                          Shape::kSphere, Shape::kEllipticCylinder, Shape::kEllipsoid};
  return kAll;
}

const std::vector<Shape>& ZooShapes() {
  static const std::vector<Shape> kZoo = {Shape::kRoundedBox, Shape::kBottle, Shape::kBlob, Shape::kMug,
                                          Shape::kBowl};
  return kZoo;
}

std::string ShapeName(Shape shape) {
  switch (shape) {
    case Shape::kCuboid:
      return "cuboid";
    case Shape::kTriangularPrism:
      return "triangular-prism";
    case Shape::kCylinder:
      return "cylinder";
    case Shape::kSphere:
      return "sphere";
    case Shape::kEllipticCylinder:
      return "elliptic-cylinder";
    case Shape::kEllipsoid:
      return "ellipsoid";
    case Shape::kRoundedBox:
      return "rounded-box";
    case Shape::kBottle:
      return "bottle";
    case Shape::kBlob:
      return "blob";
    case Shape::kMug:
      return "mug";
    case Shape::kBowl:
      return "bowl";
  }
  return "unknown";
}

std::optional<Shape> ParseShape(const std::string& name) {
  for (const std::vector<Shape>* shapes : {&AllShapes(), &ZooShapes()}) {
    for (Shape shape : *shapes) {
      if (ShapeName(shape) == name) return shape;
    }
  }
  return std::nullopt;
}

Eigen::Vector3d DefaultSize(Shape shape) {
  switch (shape) {
    case Shape::kCuboid:
      return {0.07, 0.07, 0.14};
    case Shape::kTriangularPrism:
      return {0.0693, 0.08, 0.14};
    case Shape::kCylinder:
      return {0.07, 0.07, 0.14};
    case Shape::kSphere:
      return {0.08, 0.08, 0.08};
    case Shape::kEllipticCylinder:
      return {0.09, 0.06, 0.14};
    case Shape::kEllipsoid:
      return {0.08, 0.06, 0.12};
    case Shape::kRoundedBox:
      return {0.09, 0.05, 0.16};
    case Shape::kBottle:
      return {0.07, 0.07, 0.20};
    case Shape::kBlob:
      return {0.075, 0.07, 0.08};
    case Shape::kMug:
      return {0.11, 0.08, 0.095};
    case Shape::kBowl:
      return {0.12, 0.12, 0.06};
  }
  return {0.07, 0.07, 0.14};
}

TriangleMesh MakeShape(Shape shape, const Eigen::Vector3d& size_m, int segments) {
  if (!(size_m.array() > 0.0).all() || !size_m.allFinite()) {
    throw std::invalid_argument("MakeShape: size must be positive, got " + std::to_string(size_m.x()) +
                                " x " + std::to_string(size_m.y()) + " x " + std::to_string(size_m.z()));
  }
  if (segments < 8) throw std::invalid_argument("MakeShape: segments < 8");
  const double w = size_m.x();
  const double d = size_m.y();
  const double h = size_m.z();
  switch (shape) {
    case Shape::kCuboid:
      return ExtrudeConvexPolygon({{-w / 2, -d / 2}, {w / 2, -d / 2}, {w / 2, d / 2}, {-w / 2, d / 2}}, h);
    case Shape::kTriangularPrism:
      // Apex on -x, opposite face on +x; origin at the centroid.
      return ExtrudeConvexPolygon({{-2.0 * w / 3.0, 0.0}, {w / 3.0, -d / 2}, {w / 3.0, d / 2}}, h);
    case Shape::kCylinder:
    case Shape::kEllipticCylinder:
      return ExtrudeConvexPolygon(Ellipse(w / 2, d / 2, segments), h);
    case Shape::kSphere:
    case Shape::kEllipsoid:
      return MakeEllipsoid(w / 2, d / 2, h / 2, segments);
    case Shape::kRoundedBox:
      return internal::MakeRoundedBox(size_m, segments);
    case Shape::kBottle:
      return internal::MakeBottle(size_m, segments);
    case Shape::kBlob:
      return internal::MakeBlob(size_m, segments);
    case Shape::kMug:
      return internal::MakeMug(size_m, segments);
    case Shape::kBowl:
      return internal::MakeBowl(size_m, segments);
  }
  throw std::invalid_argument("MakeShape: unknown shape");
}

double AnalyticVolume(Shape shape, const Eigen::Vector3d& size_m) {
  const double w = size_m.x();
  const double d = size_m.y();
  const double h = size_m.z();
  switch (shape) {
    case Shape::kCuboid:
      return w * d * h;
    case Shape::kTriangularPrism:
      return 0.5 * w * d * h;
    case Shape::kCylinder:
    case Shape::kEllipticCylinder:
      return M_PI * (w / 2) * (d / 2) * h;
    case Shape::kSphere:
    case Shape::kEllipsoid:
      return 4.0 / 3.0 * M_PI * (w / 2) * (d / 2) * (h / 2);
    case Shape::kRoundedBox:
      return internal::RoundedBoxVolume(size_m);
    case Shape::kBottle:
      return internal::BottleVolume(size_m);
    case Shape::kBlob:
      return internal::BlobVolume(size_m);
    case Shape::kMug:
      return internal::MugVolume(size_m);
    case Shape::kBowl:
      return internal::BowlVolume(size_m);
  }
  return 0.0;
}

TriangleMesh NormalizeToObjectFrame(const TriangleMesh& mesh) {
  const Eigen::AlignedBox3d box = mesh::Bounds(mesh);
  if (box.isEmpty()) return mesh;
  const Eigen::Vector3d centre = box.center();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(-centre.x(), -centre.y(), -box.min().z());
  return mesh.Transformed(T);
}

}  // namespace graspfill::synth
