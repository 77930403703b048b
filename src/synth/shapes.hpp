// SPDX-License-Identifier: BSD-3-Clause
// Built-in closed test objects: the symmetric shapes of the paper's
// simulation (Cui et al. 2021, section 3.1: cuboid, triangular prism,
// cylinder, sphere, elliptic cylinder, ellipsoid), and a zoo of
// household-like objects beyond the paper (rounded box, bottle, blob, mug,
// bowl; internal/zoo_shapes.hpp has their exact geometry).
//
// Object frame O: meters, +z is the object's "up" (the face the claw grasps
// from), the bounding box spans z in [0, H]. In x and y the origin is the
// bounding-box centre (for the paper's shapes their centre of symmetry;
// the mug's body axis is off it, on -x), except for the triangular prism,
// whose origin is the centroid of its triangle (so that three fingers at
// 120 degrees meet its three faces at equal radius).
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
  // The zoo (ZooShapes()):
  kRoundedBox,  ///< W x D x H box, edges rounded (radius 12% of min side)
  kBottle,      ///< capped bottle of revolution: body, shoulder, neck
  kBlob,        ///< fruit-like lumpy ellipsoid, no symmetry, box W x D x H
  kMug,         ///< lidded mug (diameter D) with a handle on +x (W - D)
  kBowl,        ///< open bowl, 4 mm wall, opening up (+z), a closed solid
};

/// The paper's six shapes (cuboid .. ellipsoid), in the order above. Only
/// these: the paper protocol, `bench repair` and the test suites that loop
/// over AllShapes() are sized for them. The zoo is in ZooShapes().
const std::vector<Shape>& AllShapes();
/// The zoo's shapes (rounded box .. bowl), in the order above.
const std::vector<Shape>& ZooShapes();

/// CLI name: cuboid, triangular-prism, cylinder, sphere, elliptic-cylinder,
/// ellipsoid, rounded-box, bottle, blob, mug, bowl.
std::string ShapeName(Shape shape);
/// Inverse of ShapeName over the paper's shapes and the zoo; nullopt for
/// an unknown name.
std::optional<Shape> ParseShape(const std::string& name);

/// Default bounding-box size (W, D, H) [m], chosen like the paper's models:
/// - cuboid 0.07 x 0.07 x 0.14 (the paper's middle size; it also uses
///   0.10 x 0.10 x 0.20 and 0.05 x 0.05 x 0.10),
/// - triangular prism 0.0693 x 0.08 x 0.14 (equilateral, 8 cm sides; the
///   apex points to -x, the face opposite it faces +x),
/// - cylinder 0.07 x 0.07 x 0.14,
/// - sphere 0.08 x 0.08 x 0.08,
/// - elliptic cylinder 0.09 x 0.06 x 0.14,
/// - ellipsoid 0.08 x 0.06 x 0.12;
/// and for the zoo, like the household objects they stand for (each held
/// by both claws in all three grasps):
/// - rounded box 0.09 x 0.05 x 0.16 (a cereal box; 6 mm edges),
/// - bottle 0.07 x 0.07 x 0.20 (neck 24.5 mm across),
/// - blob 0.075 x 0.07 x 0.08 (an apple),
/// - mug 0.11 x 0.08 x 0.095 (body 8 cm across, handle reaching 3 cm),
/// - bowl 0.12 x 0.12 x 0.06 (hemispherical, 4 mm wall).
Eigen::Vector3d DefaultSize(Shape shape);

/// Closed, consistently outward-oriented mesh of `shape` in frame O with
/// bounding box `size_m` (W, D, H) [m]. Curved surfaces use `segments`
/// facets around (and segments/2 rings from pole to pole for the sphere and
/// ellipsoid); 128 keeps the faceting error below 0.05% of the radius.
/// The size is taken as given: a cylinder with W != D is elliptic and a
/// sphere with unequal sizes an ellipsoid (so is a bottle's or a bowl's
/// section). Zoo shapes use segments / 4 facets per quarter turn of their
/// rounded edges and profiles.
/// The mug is two closed components, body and handle, whose ends are
/// hidden inside the body (see internal/zoo_shapes.hpp).
/// Throws std::invalid_argument on a non-positive size or segments < 8,
/// and for a mug whose handle does not fit (W <= D, or W - D outside
/// roughly 0.1..0.75 H).
TriangleMesh MakeShape(Shape shape, const Eigen::Vector3d& size_m, int segments = 128);

/// Volume of the exact (not faceted) shape [m^3]. Closed forms except for
/// the blob (numerical quadrature of its exact surface, ~1e-6 relative)
/// and the mug (body plus handle tube, the tube's length by quadrature; the
/// hidden handle ends counted in both, as the mesh's divergence theorem
/// does). Throws like MakeShape for a mug whose handle does not fit.
double AnalyticVolume(Shape shape, const Eigen::Vector3d& size_m);

/// Moves a user mesh into frame O: x, y centred on its bounding-box centre,
/// its lowest point at z = 0 (the mesh's +z stays "up"). Units unchanged.
TriangleMesh NormalizeToObjectFrame(const TriangleMesh& mesh);

}  // namespace graspfill::synth
