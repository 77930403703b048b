// Built-in closed test objects: the symmetric shapes of the paper's
// simulation (Cui et al. 2021, section 3.1: cuboid, triangular prism,
// cylinder, sphere, elliptic cylinder, ellipsoid).
//
// Object frame O: meters, +z is the object's "up" (the face the claw grasps
// from), the bounding box spans z in [0, H]. In x and y the origin is the
// shape's centre of symmetry: the bounding-box centre for every shape except
// the triangular prism, whose origin is the centroid of its triangle (so
// that three fingers at 120 degrees meet its three faces at equal radius).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::synth {

enum class Shape {
  kCuboid,            ///< W x D x H box
  kTriangularPrism,   ///< isosceles triangle (bbox W x D) extruded by H
  kCylinder,          ///< circular cylinder, diameter W (= D), height H
  kSphere,            ///< sphere, diameter W (= D = H)
  kEllipticCylinder,  ///< elliptic section with axes W (x) and D (y)
  kEllipsoid,         ///< ellipsoid with axes W, D, H
};

/// Every built-in shape, in the order above.
const std::vector<Shape>& AllShapes();

/// CLI name: cuboid, triangular-prism, cylinder, sphere, elliptic-cylinder,
/// ellipsoid.
std::string ShapeName(Shape shape);
/// Inverse of ShapeName; nullopt for an unknown name.
std::optional<Shape> ParseShape(const std::string& name);

/// Default bounding-box size (W, D, H) [m], chosen like the paper's models:
/// - cuboid 0.07 x 0.07 x 0.14 (the paper's middle size; it also uses
///   0.10 x 0.10 x 0.20 and 0.05 x 0.05 x 0.10),
/// - triangular prism 0.0693 x 0.08 x 0.14 (equilateral, 8 cm sides; the
///   apex points to -x, the face opposite it faces +x),
/// - cylinder 0.07 x 0.07 x 0.14,
/// - sphere 0.08 x 0.08 x 0.08,
/// - elliptic cylinder 0.09 x 0.06 x 0.14,
/// - ellipsoid 0.08 x 0.06 x 0.12.
Eigen::Vector3d DefaultSize(Shape shape);

/// Closed, consistently outward-oriented mesh of `shape` in frame O with
/// bounding box `size_m` (W, D, H) [m]. Curved surfaces use `segments`
/// facets around (and segments/2 rings from pole to pole for the sphere and
/// ellipsoid); 128 keeps the faceting error below 0.05% of the radius.
/// The size is taken as given: a cylinder with W != D is elliptic and a
/// sphere with unequal sizes an ellipsoid.
/// Throws std::invalid_argument on a non-positive size or segments < 8.
TriangleMesh MakeShape(Shape shape, const Eigen::Vector3d& size_m,
                       int segments = 128);

/// Volume of the exact (not faceted) shape [m^3].
double AnalyticVolume(Shape shape, const Eigen::Vector3d& size_m);

/// Moves a user mesh into frame O: x, y centred on its bounding-box centre,
/// its lowest point at z = 0 (the mesh's +z stays "up"). Units unchanged.
TriangleMesh NormalizeToObjectFrame(const TriangleMesh& mesh);

}  // namespace graspfill::synth
