// SPDX-License-Identifier: BSD-3-Clause
// The triangle rasterizer: pixels between a mesh's vertices are covered
// (the point splatter leaves them empty), the nearest triangle wins, a
// face turned away from the view is darker, bad triangles are skipped.
#include "graspfill/view/mesh_render.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "graspfill/core/provenance_colors.hpp"
#include "graspfill/view/cloud_render.hpp"

namespace graspfill::view {
namespace {

constexpr int kSize = 200;

RgbImage Blank() {
  RgbImage image;
  image.width = image.height = kSize;
  image.rgb.assign(static_cast<size_t>(kSize) * kSize * 3, 255);
  return image;
}

Rgb8 Pixel(const RgbImage& image, int x, int y) {
  const uint8_t* p = &image.rgb[(static_cast<size_t>(y) * image.width + x) * 3];
  return {p[0], p[1], p[2]};
}

bool IsBlank(const RgbImage& image, int x, int y) { return Pixel(image, x, y) == Rgb8{255, 255, 255}; }

// A square of edge `edge_m` in G's plane x = `x_m` (facing a camera on
// G's +x axis), its two triangles over its four corners alone.
TriangleMesh Square(double edge_m, double x_m) {
  const float h = static_cast<float>(edge_m / 2), x = static_cast<float>(x_m);
  TriangleMesh mesh;
  mesh.vertices = {{x, -h, -h}, {x, h, -h}, {x, h, h}, {x, -h, h}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

ViewAngle FromPlusX() {
  ViewAngle angle;
  angle.azimuth_deg = 0.0;
  angle.elevation_deg = 0.0;
  return angle;
}

Framing Around(double radius_m) {
  Framing framing;
  framing.radius_m = radius_m;
  return framing;
}

TEST(MeshRender, PixelsBetweenTheVerticesAreCovered) {
  const TriangleMesh square = Square(0.1, 0.0);
  RgbImage image = Blank();
  RenderMeshView(square, {}, Around(0.1), FromPlusX(), 0, 0, kSize, &image);
  // The square spans 0.1 m of 0.2 m framed by 0.92 of the view: its centre
  // and points a quarter of the way in from its corners are inside.
  const int c = kSize / 2;
  EXPECT_FALSE(IsBlank(image, c, c));
  EXPECT_FALSE(IsBlank(image, c - 20, c + 20));
  EXPECT_EQ(Pixel(image, c, c), ProvenanceColor(Provenance::kObserved));  // facing: full colour
  // Outside the square: untouched.
  EXPECT_TRUE(IsBlank(image, 5, 5));
  int covered = 0;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) covered += !IsBlank(image, x, y);
  }
  const double edge_px = 0.1 * 0.92 * 0.5 * kSize / 0.1;
  EXPECT_NEAR(covered, edge_px * edge_px, 4 * edge_px);

  // The same four vertices as points leave the centre empty.
  ObjectCloud corners;
  corners.points_G = square.vertices;
  RgbImage points = Blank();
  RenderView(corners, Around(0.1), FromPlusX(), 0, 0, kSize, &points);
  EXPECT_TRUE(IsBlank(points, c, c));
}

TEST(MeshRender, NearestTriangleWinsWhateverTheOrder) {
  // Two squares, the nearer (larger x: towards the camera on +x) symmetry
  // coloured by its vertices' provenance, drawn in both orders.
  TriangleMesh both = Square(0.1, -0.02);
  TriangleMesh near = Square(0.05, 0.02);
  for (Eigen::Vector3i& t : near.triangles) t += Eigen::Vector3i::Constant(4);
  std::vector<Provenance> provenance(4, Provenance::kObserved);
  provenance.resize(8, Provenance::kSymmetry);
  both.vertices.insert(both.vertices.end(), near.vertices.begin(), near.vertices.end());
  const auto far_triangles = both.triangles;
  both.triangles.insert(both.triangles.end(), near.triangles.begin(), near.triangles.end());
  for (int order = 0; order < 2; ++order) {
    SCOPED_TRACE(order);
    if (order == 1) {
      both.triangles = near.triangles;
      both.triangles.insert(both.triangles.end(), far_triangles.begin(), far_triangles.end());
    }
    RgbImage image = Blank();
    RenderMeshView(both, provenance, Around(0.1), FromPlusX(), 0, 0, kSize, &image);
    EXPECT_EQ(Pixel(image, kSize / 2, kSize / 2), ProvenanceColor(Provenance::kSymmetry));
    EXPECT_EQ(Pixel(image, kSize / 2 - 35, kSize / 2), ProvenanceColor(Provenance::kObserved));
  }
}

TEST(MeshRender, AFaceTurnedAwayIsDarker) {
  TriangleMesh tilted = Square(0.1, 0.0);
  const Eigen::Matrix3f turn = Eigen::AngleAxisf(1.2f, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  for (Eigen::Vector3f& v : tilted.vertices) v = turn * v;
  RgbImage image = Blank();
  RenderMeshView(tilted, {}, Around(0.1), FromPlusX(), 0, 0, kSize, &image);
  const Rgb8 lit = ProvenanceColor(Provenance::kObserved);
  const Rgb8 seen = Pixel(image, kSize / 2, kSize / 2);
  ASSERT_NE(seen, (Rgb8{255, 255, 255}));
  const double expected = 0.45 + 0.55 * std::cos(1.2);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(seen[k], lit[k] * expected, 1.0);
}

TEST(MeshRender, BadTrianglesAreSkipped) {
  TriangleMesh mesh = Square(0.1, 0.0);
  mesh.triangles.push_back({0, 1, 7});   // index out of range
  mesh.triangles.push_back({0, 0, 1});   // degenerate
  mesh.triangles.push_back({-1, 1, 2});  // negative
  mesh.vertices.push_back({NAN, 0, 0});
  mesh.triangles.push_back({0, 1, 4});  // non-finite vertex
  RgbImage image = Blank();
  RenderMeshView(mesh, {}, Around(0.1), FromPlusX(), 0, 0, kSize, &image);
  EXPECT_FALSE(IsBlank(image, kSize / 2, kSize / 2));
}

}  // namespace
}  // namespace graspfill::view
