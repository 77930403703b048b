// SPDX-License-Identifier: BSD-3-Clause
// graspfill synth --protocol paper: one cloud of the paper's simulated
// protocol (Cui et al. 2021, section 3.1), ready for `graspfill repair`.
//
// DIR/holey.ply      a dense sample of the shape with the top cut off and
//                    three claw-sized holes dug out of the side, in a random
//                    rigid pose; every point provenance observed, no normals
// DIR/gt_cloud.ply   an independent sample of the whole surface, same pose
// DIR/protocol.json  the arguments, the pose and the claw hole centres
#include "cmd_synth_protocol.hpp"

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <system_error>
#include <vector>

#include "graspfill/io/atomic_file.hpp"
#include "graspfill/io/ply.hpp"
#include "output_dir.hpp"
#include "synth/paper_protocol.hpp"

namespace graspfill::cli {
namespace {

namespace fs = std::filesystem;
// Ordered: protocol.json reads top-down, format and doc first.
using ordered_json = nlohmann::ordered_json;

constexpr const char* kHoleyFile = "holey.ply";
constexpr const char* kTruthFile = "gt_cloud.ply";
constexpr const char* kProtocolFile = "protocol.json";

// The clouds are in the protocol's "cloud" frame (the random pose), which
// protocol.json relates to the object frame; there is no gripper or camera.
constexpr const char* kCloudFrameName = "cloud";

ordered_json OrderedVec(const Eigen::Vector3d& v) { return ordered_json::array({v.x(), v.y(), v.z()}); }

ordered_json MatrixRows(const Eigen::Isometry3d& T) {
  ordered_json rows = ordered_json::array();
  for (int r = 0; r < 4; ++r) rows.push_back(ordered_json::array({T(r, 0), T(r, 1), T(r, 2), T(r, 3)}));
  return rows;
}

ObjectCloud MakeCloud(const std::vector<Eigen::Vector3f>& points) {
  ObjectCloud cloud;
  cloud.frame_name = kCloudFrameName;
  cloud.points_G = points;
  // Explicit rather than left empty: the repair's input is all observed.
  cloud.provenance.assign(points.size(), Provenance::kObserved);
  return cloud;
}

// Only file names, never the output folder: the same arguments must give
// the same bytes wherever they are written.
ordered_json ProtocolJson(const SynthProtocolOptions& o, const synth::PaperProtocolCloud& c) {
  ordered_json centres = ordered_json::array();
  for (const Eigen::Vector3d& centre : c.claw_hole_centres) centres.push_back(OrderedVec(centre));
  return {
      {"format", "graspfill-synth-protocol/1"},
      {"doc",
       "the simulated protocol of Cui et al. 2021, section 3.1: a dense sample of the "
       "shape, the top cut off, three claw-sized holes dug out of the side, a random "
       "rigid pose; ground truth an independent sample of the whole surface"},
      {"frames_doc",
       "object frame: z up, base at z = 0, x and y centred on the shape; "
       "T_cloud_object maps object points into the clouds' frame; meters"},
      {"protocol", "paper"},
      {"shape", synth::ShapeName(o.shape)},
      {"size_m", OrderedVec(c.size_m)},
      {"grasp", synth::GraspWayName(o.grasp)},
      {"seed", o.seed},
      {"points", o.points},
      {"holey", {{"file", kHoleyFile}, {"points", c.holey.size()}}},
      {"ground_truth", {{"file", kTruthFile}, {"points", c.ground_truth.size()}}},
      {"T_cloud_object", MatrixRows(c.T_cloud_object)},
      {"claw_hole_centres", centres},
      {"claw_hole_centres_doc",
       "one per claw hole, cloud frame: a marker near the surface, not a surface point"},
  };
}

}  // namespace

int RunSynthProtocol(const SynthProtocolOptions& o) {
  const fs::path dir(o.output_dir);
  const fs::path holey_path = dir / kHoleyFile;
  const fs::path truth_path = dir / kTruthFile;
  const fs::path json_path = dir / kProtocolFile;
  // Refused without --force before anything is generated: an existing or
  // linked output, or one that cannot be written.
  if (!o.force) {
    std::vector<std::string> existing;
    for (const fs::path& path : {holey_path, truth_path, json_path}) {
      std::error_code ec;
      if (fs::exists(fs::symlink_status(path, ec))) existing.push_back(path.string());
    }
    if (!existing.empty()) {
      std::fprintf(stderr, "graspfill synth: refusing to overwrite existing output (use --force):\n");
      for (const std::string& path : existing) std::fprintf(stderr, "  %s\n", path.c_str());
      return 1;
    }
  }

  synth::PaperProtocolConfig config;
  config.shape = o.shape;
  config.size_m = o.size_m;
  config.grasp = o.grasp;
  config.num_points = o.points;
  config.seed = o.seed;
  // Generated before the folder is made, so a failure leaves nothing behind.
  const synth::PaperProtocolCloud cloud = synth::MakePaperProtocolCloud(config);

  if (!PrepareOutputs(dir, {kHoleyFile, kTruthFile, kProtocolFile}, o.force, "synth")) return 1;
  const io::IfExists if_exists = io::ReplaceIf(o.force);
  io::WriteCloudPly(holey_path.string(), MakeCloud(cloud.holey), if_exists);
  io::WriteCloudPly(truth_path.string(), MakeCloud(cloud.ground_truth), if_exists);
  io::WriteFileAtomically(json_path.string(), ProtocolJson(o, cloud).dump(2) + "\n", "cannot write",
                          if_exists);
  std::printf("wrote %s: %zu points (%s, top cut, %zu claw holes); truth %s: %zu points; %s\n",
              holey_path.string().c_str(), cloud.holey.size(), synth::ShapeName(o.shape).c_str(),
              cloud.claw_hole_centres.size(), truth_path.string().c_str(), cloud.ground_truth.size(),
              json_path.string().c_str());
  return 0;
}

}  // namespace graspfill::cli
