// SPDX-License-Identifier: BSD-3-Clause
// graspfill synth --grasps S1,S2,...: one recording of several grasps in
// turn (docs/live.md, "Grasp after grasp"): grasp k holds shape k, its gripper
// states carry grasp_id k (1, 2, ...), and a second without events
// separates the grasps (the robot putting one object down and taking the
// next). Ground truth per grasp in DIR/grasp<k>/.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::cli {

struct SynthGraspsOptions {
  std::vector<std::string> shapes;  ///< one per grasp, in order
  std::string claw{"three-finger"};
  std::string grasp{"top-straight"};
  uint64_t seed{1};  ///< grasp k uses seed + k - 1
  int frames{90};    ///< depth frames per grasp
  bool ideal{false};
  double wall_m{0.0};
  CameraIntrinsics intrinsics;  ///< the camera (--width, --height)
  bool force{false};
  std::string output_dir;
};

/// Splits "a,b,c" (no empty names); throws UsageError naming an unknown shape.
std::vector<std::string> ParseGraspShapes(const std::string& text);

/// Writes DIR/recording.lcmlog (the session description first), and per
/// grasp DIR/grasp<k>/gt_mesh.ply and gt_cloud.ply; DIR/grasps.json lists
/// them. Returns the exit code (1 with a message on stderr on failure).
int RunSynthGrasps(const SynthGraspsOptions& options);

}  // namespace graspfill::cli
