// SPDX-License-Identifier: BSD-3-Clause
// Depth rendering with Embree: meshes rigid in the gripper frame G are
// committed once; each frame casts the camera's rays transformed into G.
// Rays are only cast inside the projection of the meshes' bounding box;
// the background wall is analytic.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "graspfill/core/raycaster.hpp"
#include "graspfill/types.hpp"
#include "synth/scene.hpp"
#include "synth/sensor_model.hpp"

namespace graspfill::synth {

/// Ideal z-depth renderer for meshes in G plus a fronto-parallel wall.
/// Render() is const and allocation-free apart from the output image; NOT
/// safe to call while adding meshes.
class DepthRenderer {
 public:
  /// @param intrinsics pinhole model of the rendered images
  /// @param wall_distance_m z of a wall perpendicular to the optical axis
  ///        in C [m]; 0 for no wall.
  DepthRenderer(const CameraIntrinsics& intrinsics, double wall_distance_m);

  /// Adds a mesh given in G with the label its pixels get. Call Commit()
  /// after the last one.
  void AddMesh(const TriangleMesh& mesh_G, SurfaceLabel label);
  void Commit();

  /// Marks what `sensor` leaves unlit (IdealDepthImage::unlit): the
  /// projector's shadow, and dark patches on the object's pixels (drawn
  /// from `seed`, over this renderer's frame, the object's own). Call
  /// after Commit(); nothing is marked by default.
  void SetUnlit(const SensorModelConfig& sensor, uint64_t seed);

  /// Renders the scene with the gripper at `T_C_G` (maps p_G to p_C).
  void Render(const Eigen::Isometry3d& T_C_G, IdealDepthImage* out) const;

  const CameraIntrinsics& intrinsics() const { return intrinsics_; }

 private:
  CameraIntrinsics intrinsics_;
  double wall_distance_m_;
  Raycaster raycaster_;
  std::vector<SurfaceLabel> labels_;  ///< by Embree geometry id
  Eigen::AlignedBox3d bounds_G_;
  // What SetUnlit asked for.
  bool projector_shadow_{false};
  Eigen::Vector3d projector_C_{0.0, 0.0, 0.0};
  double patch_share_{0.0};
  double patch_cell_m_{0.01};
  uint64_t patch_seed_{0};
  double patch_threshold_{1.0};  // the field's value above which a point is dark
};

/// Renders the frames of a Scene (object, claw, arm, wall) with its sensor
/// model. Keeps a reference: the scene must outlive it. With a slip the
/// object has its own renderer (it moves in G, the rest does not) and is
/// laid over the rest by depth; without one everything is in one.
class SceneRenderer {
 public:
  explicit SceneRenderer(const Scene& scene);

  /// The noise-free image of frame `frame_index` (at Scene::DepthUtime).
  IdealDepthImage RenderIdeal(int frame_index) const;
  /// Frame `frame_index` through the sensor model, seeded by
  /// DeriveSeed(scene seed, frame_index): rendering a frame twice gives
  /// byte-identical depth.
  DepthFrame Render(int frame_index) const;

 private:
  const Scene& scene_;
  DepthRenderer renderer_;
  DepthRenderer object_renderer_;  ///< the object alone, with a slip only
};

}  // namespace graspfill::synth
