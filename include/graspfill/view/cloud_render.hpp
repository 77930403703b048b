// SPDX-License-Identifier: BSD-3-Clause
// Pictures of object clouds for people: a software point splatter (each
// point a disc, nearest wins through a z-buffer), orthographic, in the
// points' provenance colours. Needs no display (Open3D's visualizer does).
//
// Pure functions; reentrant, any thread.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::view {

/// Where the views look and how much they hold: a sphere in G that every
/// view shows whole, the same for all clouds of a picture so that they
/// compare at one scale.
struct Framing {
  Eigen::Vector3d center_G{Eigen::Vector3d::Zero()};
  double radius_m{0.1};
};

/// The bounding box of all finite points of `clouds`, its centre and
/// half-diagonal (0.1 m around the origin when there is no point).
Framing FrameClouds(const std::vector<const ObjectCloud*>& clouds);

/// Where the camera looks from. G's +z (the approach direction, away from
/// the palm) points down in the picture, so the palm side is on top.
struct ViewAngle {
  double azimuth_deg{0.0};     ///< about G's z axis, from +x towards +y
  double elevation_deg{30.0};  ///< above the horizontal, from the palm's side
};

/// Draws `cloud` into the `size_px` x `size_px` square of *image whose
/// top-left pixel is (x0, y0), over what is there. Points take their
/// provenance colour (core/provenance_colors.hpp) times a shade in
/// [0.45, 1]: by the angle of their normal to the view when the cloud has
/// normals (1 facing the camera), else by depth (1 at the framing sphere's
/// near side, 0.6 at its far side); the disc radius follows the cloud's
/// point spacing.
void RenderView(const ObjectCloud& cloud, const Framing& framing, const ViewAngle& angle, int x0, int y0,
                int size_px, RgbImage* image);

}  // namespace graspfill::view
