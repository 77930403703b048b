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
};

// Pixels of exactly `colour` in columns [x0, x1) and rows [y0, y1).
ColourStats Find(const RgbImage& image, const Rgb8& colour, int x0, int x1, int y0, int y1) {
  ColourStats s;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const uint8_t* p = &image.rgb[(static_cast<size_t>(y) * image.width + x) * 3];
      if (p[0] == colour[0] && p[1] == colour[1] && p[2] == colour[2]) {
        ++s.count;
        s.mean_row += y;
      }
    }
  }
  if (s.count > 0) s.mean_row /= s.count;
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

TEST(ContactSheetTest, NormalsShadeTheColourTowardsDark) {
  ObjectCloud cloud = HeldCylinder();
  for (const Eigen::Vector3f& p : cloud.points_G) {
    // Radial on the side; the cap faces the palm.
    cloud.normals_G.push_back(p.z() == 0.0f ? Eigen::Vector3f(0, 0, -1)
                                             : Eigen::Vector3f(p.x(), p.y(), 0).normalized());
  }
  SheetConfig config;
  config.views = 1;
  const RgbImage image = RenderSheet({{&cloud, "shaded"}}, config);
  const Region view = ViewRegion(LayoutSheet(1, config), 0, 0);
  // Edge-on parts of the side are darker than the flat colour: fewer
  // pixels keep it exactly than without normals.
  ObjectCloud flat = cloud;
  flat.normals_G.clear();
  const RgbImage flat_image = RenderSheet({{&flat, "flat"}}, config);
  EXPECT_LT(Find(image, Provenance::kObserved, view).count,
            Find(flat_image, Provenance::kObserved, view).count / 2);
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
