// SPDX-License-Identifier: BSD-3-Clause
// The paper's simulated protocol (Cui et al. 2021, section 3.1): a dense
// sample of a shape's surface with the top cut off, three claw-sized holes
// dug out of the side, in a random rigid pose; and an independent sample of
// the whole surface as ground truth, in the same pose.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "synth/scene.hpp"
#include "synth/shapes.hpp"

namespace graspfill::synth {

struct PaperProtocolConfig {
  Shape shape{Shape::kCuboid};
  /// Bounding box W x D x H [m]; zero = the shape's default size.
  Eigen::Vector3d size_m{0, 0, 0};
  GraspWay grasp{GraspWay::kTopStraight};
  /// Points of the complete surface before cutting (the ground truth has
  /// as many). 50k is ~1 mm spacing on the paper's 10 x 10 x 20 cm cuboid.
  int num_points{50000};
  /// The unseen top: a shape with a flat top (cuboid, prisms, cylinders)
  /// loses that face only, since a camera beside it sees the side walls up
  /// to the rim (cutting a band of wall off too would make the height
  /// unobservable, a different problem from the paper's); a round top
  /// (sphere, ellipsoid) loses the cap above (1 - this) x its height.
  double round_top_cut_fraction{0.08};
  /// When > 0, every shape loses the band above (1 - this) x its height
  /// instead (a cut through the walls: the top's height is then not in the
  /// cloud; `graspfill bench repair --top-cut` measures 0.02 and 0.15).
  double top_cut_fraction{0.0};
  /// Claw holes: the paper keeps them the same size for every object.
  int num_claw_holes{3};
  double claw_hole_width_m{0.025};   ///< along the surface, across the finger
  double claw_hole_height_m{0.045};  ///< along the finger
  /// Tilt of the fingers for oblique grasps [rad] (about the radial axis).
  double oblique_tilt_rad{0.35};
  /// Place the cloud in a random rigid pose (else the object frame: z up).
  bool random_pose{true};
  uint64_t seed{1};
};

struct PaperProtocolCloud {
  std::vector<Eigen::Vector3f> holey;         ///< the input to repair
  std::vector<Eigen::Vector3f> ground_truth;  ///< independent complete sample
  /// Object frame (z up, base at z = 0) -> cloud frame.
  Eigen::Isometry3d T_cloud_object{Eigen::Isometry3d::Identity()};
  Eigen::Vector3d size_m{0, 0, 0};
  /// Centres of the claw holes on the surface, in the cloud frame.
  std::vector<Eigen::Vector3d> claw_hole_centres;
};

/// Height [m] in the object frame (base at z = 0) above which the protocol
/// cuts the top off (see PaperProtocolConfig::round_top_cut_fraction).
double TopCutZ(const PaperProtocolConfig& config, double height_m);

/// Deterministic for a given config. Throws std::invalid_argument on a
/// non-positive size or point count.
PaperProtocolCloud MakePaperProtocolCloud(const PaperProtocolConfig& config);

}  // namespace graspfill::synth
