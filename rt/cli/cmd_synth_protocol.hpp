// SPDX-License-Identifier: BSD-3-Clause
// `graspfill synth --protocol paper`: the paper's simulated test clouds
// (Cui et al. 2021, section 3.1) for `graspfill repair`. cmd_synth.cpp parses
// and checks the arguments; cmd_synth_protocol.cpp writes the files.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "synth/scene.hpp"
#include "synth/shapes.hpp"

namespace graspfill::cli {

struct SynthProtocolOptions {
  synth::Shape shape{synth::Shape::kCuboid};
  /// Bounding box W x D x H [m]; zero = the shape's default size.
  Eigen::Vector3d size_m{0, 0, 0};
  synth::GraspWay grasp{synth::GraspWay::kTopStraight};
  uint64_t seed{1};
  /// Points sampled on the whole surface (the ground truth has as many).
  int points{50000};
  bool force{false};
  std::string output_dir;
};

/// --points range. 1000 points are ~1 cm apart on the paper's largest cuboid
/// (10 x 10 x 20 cm), a claw hole then spans about a dozen; 5 million are
/// ~0.15 mm apart, a 65 MB PLY, beyond which a typo is likelier than intent.
constexpr int kMinProtocolPoints = 1000;
constexpr int kMaxProtocolPoints = 5000000;

/// Writes DIR/holey.ply, gt_cloud.ply and protocol.json. Returns the exit
/// code: 0, or 1 (message on stderr) if outputs exist without `force` or a
/// file cannot be written. Throws on a failure of the generator itself.
int RunSynthProtocol(const SynthProtocolOptions& options);

}  // namespace graspfill::cli
