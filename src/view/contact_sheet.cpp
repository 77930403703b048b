// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/view/contact_sheet.hpp"

#include <array>
#include <stdexcept>

#include "bitmap_font.hpp"
#include "graspfill/core/provenance_colors.hpp"
#include "graspfill/view/cloud_render.hpp"
#include "graspfill/view/mesh_render.hpp"

namespace graspfill::view {
namespace {

constexpr int kMarginPx = 12;
constexpr int kTextScale = 2;
constexpr int kLineHeightPx = kGlyphHeight * kTextScale + 6;
constexpr int kSwatchPx = kGlyphHeight * kTextScale;
constexpr Rgb8 kBackground = {255, 255, 255};
constexpr Rgb8 kViewBackground = {246, 246, 246};
constexpr Rgb8 kText = {40, 40, 40};
constexpr Rgb8 kFaintText = {150, 150, 150};
constexpr std::array<Provenance, 3> kProvenances = {Provenance::kObserved, Provenance::kSurface,
                                                    Provenance::kSymmetry};

void FillRect(int x0, int y0, int w, int h, const Rgb8& color, RgbImage* image) {
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = x0; x < x0 + w; ++x) {
      uint8_t* p = &image->rgb[(static_cast<size_t>(y) * image->width + x) * 3];
      p[0] = color[0];
      p[1] = color[1];
      p[2] = color[2];
    }
  }
}

std::string CountsLine(const ObjectCloud& cloud, const TriangleMesh* mesh) {
  if (mesh != nullptr) {
    return std::to_string(mesh->triangles.size()) + " triangles, " + std::to_string(mesh->vertices.size()) +
           " vertices";
  }
  size_t added = 0;
  for (const Provenance p : cloud.provenance) added += p != Provenance::kObserved;
  return std::to_string(cloud.size()) + " points, " + std::to_string(added) + " added";
}

}  // namespace

void SheetConfig::Validate() const {
  if (views < 1 || views > 12) {
    throw std::invalid_argument("views must be 1..12, not " + std::to_string(views));
  }
  if (view_px < 64 || view_px > 2048) {
    throw std::invalid_argument("view_px must be 64..2048, not " + std::to_string(view_px));
  }
  if (!(elevation_deg >= -80.0 && elevation_deg <= 80.0)) {
    throw std::invalid_argument("elevation_deg must be -80..80, not " + std::to_string(elevation_deg));
  }
}

int SheetLayout::ViewX(int column) const { return kMarginPx + column * (view_px + kMarginPx); }

int SheetLayout::ViewY(int view) const { return views_y + view * (view_px + kMarginPx); }

SheetLayout LayoutSheet(int columns, const SheetConfig& config) {
  config.Validate();
  if (columns < 1) throw std::invalid_argument("LayoutSheet: no cloud to draw");
  SheetLayout layout;
  layout.columns = columns;
  layout.views = config.views;
  layout.view_px = config.view_px;
  layout.views_y = kMarginPx + 2 * kLineHeightPx + kMarginPx / 2;  // below two lines of title
  layout.legend_y = layout.ViewY(config.views);
  layout.width = layout.ViewX(columns);
  layout.height = layout.legend_y + static_cast<int>(kProvenances.size()) * kLineHeightPx + kMarginPx;
  return layout;
}

RgbImage RenderSheet(const std::vector<SheetCloud>& clouds, const SheetConfig& config) {
  const SheetLayout layout = LayoutSheet(static_cast<int>(clouds.size()), config);
  std::vector<const ObjectCloud*> all;
  for (const SheetCloud& c : clouds) {
    if (c.cloud == nullptr) throw std::invalid_argument("RenderSheet: a null cloud");
    if (c.mesh != nullptr && c.mesh->vertices.size() != c.cloud->size()) {
      throw std::invalid_argument("RenderSheet: a mesh whose vertices are not its cloud's points");
    }
    all.push_back(c.cloud);
  }
  RgbImage image;
  image.width = layout.width;
  image.height = layout.height;
  image.rgb.resize(static_cast<size_t>(image.width) * image.height * 3);
  FillRect(0, 0, image.width, image.height, kBackground, &image);

  const Framing framing = FrameClouds(all);
  for (int c = 0; c < layout.columns; ++c) {
    const int x0 = layout.ViewX(c);
    const ObjectCloud& cloud = *clouds[c].cloud;
    DrawText(FitText(clouds[c].title, config.view_px, kTextScale), x0, kMarginPx, kTextScale, kText, &image);
    DrawText(FitText(CountsLine(cloud, clouds[c].mesh), config.view_px, kTextScale), x0,
             kMarginPx + kLineHeightPx, kTextScale, kFaintText, &image);
    for (int v = 0; v < layout.views; ++v) {
      const int y0 = layout.ViewY(v);
      FillRect(x0, y0, config.view_px, config.view_px, kViewBackground, &image);
      ViewAngle angle;
      angle.azimuth_deg = 360.0 * v / config.views;
      angle.elevation_deg = config.elevation_deg;
      if (clouds[c].mesh != nullptr) {
        RenderMeshView(*clouds[c].mesh, cloud.provenance, framing, angle, x0, y0, config.view_px, &image);
      } else {
        RenderView(cloud, framing, angle, x0, y0, config.view_px, &image);
      }
    }
  }
  int y = layout.legend_y;
  for (const Provenance p : kProvenances) {
    FillRect(kMarginPx, y, kSwatchPx, kSwatchPx, ProvenanceColor(p), &image);
    DrawText(ProvenanceLabel(p), kMarginPx + kSwatchPx + 8, y, kTextScale, kText, &image);
    y += kLineHeightPx;
  }
  return image;
}

}  // namespace graspfill::view
