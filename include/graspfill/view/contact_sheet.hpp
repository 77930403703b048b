// SPDX-License-Identifier: BSD-3-Clause
// One picture of one or more object clouds (e.g. before and after the
// repair): a column per cloud, a row per view, all at one scale, each
// column titled with the cloud's name and point counts, and a legend of
// the provenance colours.
//
// Pure functions; reentrant, any thread.
#pragma once

#include <string>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::view {

struct SheetConfig {
  /// Views per cloud, evenly spaced about G's z axis (1..12) [count].
  int views{3};
  /// Edge of each (square) view, 64..2048 [pixels].
  int view_px{360};
  /// The camera above the horizontal, from the palm's side, -80..80 [deg].
  double elevation_deg{30.0};

  /// @throws std::invalid_argument naming the field out of range.
  void Validate() const;
};

struct SheetCloud {
  const ObjectCloud* cloud{nullptr};
  std::string title;  ///< e.g. the file's name; cut to the column's width
  /// A mesh whose vertices are `cloud` (same order): drawn as filled
  /// triangles (view/mesh_render.hpp) instead of the cloud's points; null:
  /// the points.
  const TriangleMesh* mesh{nullptr};
};

/// Where RenderSheet puts things [pixels, from the top-left corner].
struct SheetLayout {
  int width{0};
  int height{0};
  int view_px{0};
  int views_y{0};   ///< top of the first row of views
  int legend_y{0};  ///< top of the legend, below the views
  int columns{0};
  int views{0};
  /// Top-left pixel of view `view` of cloud `column`.
  int ViewX(int column) const;
  int ViewY(int view) const;
};

/// The layout of a sheet of `columns` clouds.
/// @throws std::invalid_argument on a bad config or columns < 1.
SheetLayout LayoutSheet(int columns, const SheetConfig& config);

/// Renders the sheet (see the file comment). Pixels: white background,
/// points in their provenance colours (view/cloud_render.hpp), meshes as
/// shaded surfaces (view/mesh_render.hpp), dark text.
/// @throws std::invalid_argument on a bad config, no cloud or a null one.
RgbImage RenderSheet(const std::vector<SheetCloud>& clouds, const SheetConfig& config);

}  // namespace graspfill::view
