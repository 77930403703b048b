// SPDX-License-Identifier: BSD-3-Clause
// Pictures of clouds: each provenance's colour where its points are, the
// legend, before / after columns at one scale, and the config's checks.
#include "graspfill/view/contact_sheet.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "graspfill/core/provenance_colors.hpp"

namespace graspfill::view {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A 6 cm-wide, 12 cm-tall cylinder's side in G (+z away from the palm),
// observed; its top cap (the palm side, z = 0) filled by symmetry; a strip
// of the side all round at mid-height filled from the surface.
ObjectCloud HeldCylinder() {
  ObjectCloud cloud;
  constexpr double kRadius = 0.03, kHeight = 0.12;
  for (int k = 0; k < 120; ++k) {
    const double z = kHeight * (k + 0.5) / 120;
    for (int a = 0; a < 120; ++a) {
      const double t = 2 * kPi * a / 120;
      cloud.points_G.emplace_back(kRadius * std::cos(t), kRadius * std::sin(t), z);
      const bool strip = z > 0.055 && z < 0.065;
      cloud.provenance.push_back(strip ? Provenance::kSurface : Provenance::kObserved);
    }
  }
  for (int r = 1; r <= 30; ++r) {
    for (int a = 0; a < 6 * r; ++a) {
      const double t = 2 * kPi * a / (6 * r);
      cloud.points_G.emplace_back(kRadius * r / 30 * std::cos(t), kRadius * r / 30 * std::sin(t), 0.0);
      cloud.provenance.push_back(Provenance::kSymmetry);
    }
  }
  return cloud;
}

struct ColourStats {
  int count{0};
  double mean_row{0.0};
  double mean_shade{0.0};
};

// The shade s in [0.4, 1] with pixel ~= s * colour (to rounding), or -1:
// the palette's hues are far apart, so a pixel is a shade of one at most.
double ShadeOf(const uint8_t* pixel, const Rgb8& colour) {
  double dot = 0.0, norm = 0.0;
  for (int k = 0; k < 3; ++k) {
    dot += pixel[k] * static_cast<double>(colour[k]);
    norm += static_cast<double>(colour[k]) * colour[k];
  }
  const double s = dot / norm;
  if (s < 0.4 || s > 1.01) return -1.0;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(pixel[k] - s * colour[k]) > 1.5) return -1.0;
  }
  return s;
}

// Pixels of a shade of `colour` in columns [x0, x1) and rows [y0, y1).
ColourStats Find(const RgbImage& image, const Rgb8& colour, int x0, int x1, int y0, int y1) {
  ColourStats s;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const double shade = ShadeOf(&image.rgb[(static_cast<size_t>(y) * image.width + x) * 3], colour);
      if (shade < 0.0) continue;
      ++s.count;
      s.mean_row += y;
      s.mean_shade += shade;
    }
  }
  if (s.count > 0) {
    s.mean_row /= s.count;
    s.mean_shade /= s.count;
  }
  return s;
}

struct Region {
  int x0, x1, y0, y1;
};

Region ViewRegion(const SheetLayout& layout, int column, int view) {
  return {layout.ViewX(column), layout.ViewX(column) + layout.view_px, layout.ViewY(view),
          layout.ViewY(view) + layout.view_px};
}

ColourStats Find(const RgbImage& image, Provenance p, const Region& r) {
  return Find(image, ProvenanceColor(p), r.x0, r.x1, r.y0, r.y1);
}

// The lowest row of the view holding `colour` (-1 if none).
int BottomRow(const RgbImage& image, Provenance p, const Region& r) {
  for (int y = r.y1 - 1; y >= r.y0; --y) {
    if (Find(image, ProvenanceColor(p), r.x0, r.x1, y, y + 1).count > 0) return y;
  }
  return -1;
}

TEST(ContactSheetTest, EachProvenanceColourWhereItsPointsAre) {
  const ObjectCloud cloud = HeldCylinder();
  SheetConfig config;
  config.views = 3;
  const RgbImage image = RenderSheet({{&cloud, "cylinder"}}, config);
  const SheetLayout layout = LayoutSheet(1, config);
  ASSERT_EQ(image.width, layout.width);
  ASSERT_EQ(image.height, layout.height);
  ASSERT_EQ(image.rgb.size(), static_cast<size_t>(image.width) * image.height * 3);
  for (int v = 0; v < config.views; ++v) {
    SCOPED_TRACE("view " + std::to_string(v));
    const Region view = ViewRegion(layout, 0, v);
    const ColourStats observed = Find(image, Provenance::kObserved, view);
    const ColourStats surface = Find(image, Provenance::kSurface, view);
    const ColourStats symmetry = Find(image, Provenance::kSymmetry, view);
    EXPECT_GT(observed.count, 1000);
    EXPECT_GT(surface.count, 100);
    EXPECT_GT(symmetry.count, 100);
    // The palm side (the cap, z = 0) on top, the strip (z = 6 cm) below
    // it, the observed side reaching below the strip (to z = 12 cm).
    EXPECT_LT(symmetry.mean_row, surface.mean_row);
    EXPECT_GT(BottomRow(image, Provenance::kObserved, view),
              BottomRow(image, Provenance::kSurface, view) + 20);
    // The object stays inside its view, clear of the others.
    EXPECT_GT(observed.mean_row, view.y0 + 0.25 * layout.view_px);
    EXPECT_LT(observed.mean_row, view.y0 + 0.75 * layout.view_px);
  }
  // The legend: a swatch of each colour below the views.
  const Region legend{0, image.width, layout.legend_y, image.height};
  for (const Provenance p : {Provenance::kObserved, Provenance::kSurface, Provenance::kSymmetry}) {
    EXPECT_GE(Find(image, p, legend).count, 100) << ProvenanceLabel(p);
  }
}

TEST(ContactSheetTest, BeforeAndAfterSideBySideAtOneScale) {
  const ObjectCloud after = HeldCylinder();
  ObjectCloud before;
  for (size_t i = 0; i < after.size(); ++i) {
    if (after.provenance[i] != Provenance::kObserved) continue;
    before.points_G.push_back(after.points_G[i]);
    before.provenance.push_back(Provenance::kObserved);
  }
  SheetConfig config;
  config.views = 1;
  const RgbImage image = RenderSheet({{&before, "before"}, {&after, "after"}}, config);
  const SheetLayout layout = LayoutSheet(2, config);
  const Region left = ViewRegion(layout, 0, 0);
  const Region right = ViewRegion(layout, 1, 0);
  EXPECT_GT(Find(image, Provenance::kObserved, left).count, 1000);
  EXPECT_EQ(Find(image, Provenance::kSurface, left).count, 0);
  EXPECT_EQ(Find(image, Provenance::kSymmetry, left).count, 0);
  EXPECT_GT(Find(image, Provenance::kSurface, right).count, 100);
  EXPECT_GT(Find(image, Provenance::kSymmetry, right).count, 100);
  // One framing for both: the side's far end lands on the same row.
  EXPECT_EQ(BottomRow(image, Provenance::kObserved, left) - left.y0,
            BottomRow(image, Provenance::kObserved, right) - right.y0);
}

TEST(ContactSheetTest, SameCloudsGiveTheSamePixels) {
  const ObjectCloud cloud = HeldCylinder();
  const RgbImage a = RenderSheet({{&cloud, "a"}}, SheetConfig{});
  const RgbImage b = RenderSheet({{&cloud, "a"}}, SheetConfig{});
  EXPECT_EQ(a.rgb, b.rgb);
}

// A 2 x 2 cm plate of points, seen in the one view of azimuth 0: with
// normals towards the camera in full colour, with normals across the view
// at the darkest shade.
TEST(ContactSheetTest, NormalsShadeTheColour) {
  SheetConfig config;
  config.views = 1;
  const double el = config.elevation_deg * kPi / 180.0;
  const Eigen::Vector3f to_camera(static_cast<float>(std::cos(el)), 0.0f, static_cast<float>(-std::sin(el)));
  ObjectCloud facing, edge_on;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) {
      const Eigen::Vector3f p(0.0f, 0.0005f * i, 0.0005f * j);
      facing.points_G.push_back(p);
      facing.normals_G.push_back(to_camera);
      edge_on.points_G.push_back(p);
      edge_on.normals_G.push_back(Eigen::Vector3f(0, 1, 0));  // across the view
    }
  }
  facing.provenance.assign(facing.size(), Provenance::kObserved);
  edge_on.provenance.assign(edge_on.size(), Provenance::kObserved);
  const Region view = ViewRegion(LayoutSheet(1, config), 0, 0);
  const ColourStats lit = Find(RenderSheet({{&facing, "facing"}}, config), Provenance::kObserved, view);
  const ColourStats dark = Find(RenderSheet({{&edge_on, "edge-on"}}, config), Provenance::kObserved, view);
  ASSERT_GT(lit.count, 1000);
  ASSERT_GT(dark.count, 1000);
  EXPECT_GT(lit.mean_shade, 0.98);
  EXPECT_LT(dark.mean_shade, 0.5);
}

// Without normals nearer is brighter: of two plates beside each other, the
// one nearer the camera (azimuth 0: towards +x) is lighter.
TEST(ContactSheetTest, WithoutNormalsNearerIsBrighter) {
  ObjectCloud cloud;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) {
      cloud.points_G.emplace_back(0.05f, 0.0005f * i + 0.01f, 0.0005f * j);    // near, one side
      cloud.points_G.emplace_back(-0.05f, -0.0005f * i - 0.01f, 0.0005f * j);  // far, the other
    }
  }
  cloud.provenance.assign(cloud.size(), Provenance::kObserved);
  SheetConfig config;
  config.views = 1;
  const RgbImage image = RenderSheet({{&cloud, "plates"}}, config);
  const Region view = ViewRegion(LayoutSheet(1, config), 0, 0);
  const int mid = (view.x0 + view.x1) / 2;
  // +y is on the left seen from +x (the palm side up).
  const ColourStats left =
      Find(image, ProvenanceColor(Provenance::kObserved), view.x0, mid, view.y0, view.y1);
  const ColourStats right =
      Find(image, ProvenanceColor(Provenance::kObserved), mid, view.x1, view.y0, view.y1);
  ASSERT_GT(left.count, 500);
  ASSERT_GT(right.count, 500);
  EXPECT_GT(left.mean_shade, right.mean_shade + 0.2);
}

TEST(ContactSheetTest, EmptyCloudStillDraws) {
  const ObjectCloud empty;
  const RgbImage image = RenderSheet({{&empty, "empty"}}, SheetConfig{});
  EXPECT_GT(image.width, 0);
  EXPECT_EQ(Find(image, Provenance::kObserved, ViewRegion(LayoutSheet(1, SheetConfig{}), 0, 0)).count, 0);
}

TEST(ContactSheetTest, BadConfigOrNoCloudThrows) {
  const ObjectCloud cloud = HeldCylinder();
  SheetConfig config;
  config.views = 0;
  EXPECT_THROW(RenderSheet({{&cloud, "a"}}, config), std::invalid_argument);
  config = SheetConfig{};
  config.view_px = 10;
  EXPECT_THROW(RenderSheet({{&cloud, "a"}}, config), std::invalid_argument);
  config = SheetConfig{};
  config.elevation_deg = 90.0;
  EXPECT_THROW(RenderSheet({{&cloud, "a"}}, config), std::invalid_argument);
  EXPECT_THROW(RenderSheet({}, SheetConfig{}), std::invalid_argument);
  EXPECT_THROW(RenderSheet({{nullptr, "null"}}, SheetConfig{}), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::view
