// SPDX-License-Identifier: BSD-3-Clause
// graspfill synth: writes a synthetic recording (LCM log of depth frames and
// gripper states) and its ground truth, all from a graspfill::synth::Scene.
//
// DIR/recording.lcmlog  a session_description_t first (the claw exactly as
//                       rendered), then depth_image_t (ZLIB16, 1 mm units)
//                       and gripper_state_t events in time order, each
//                       event's log timestamp = its message utime
// DIR/gt_mesh.ply       the object's surface in G (where it ends: after a
//                       --slip-mm slip)
// DIR/gt_cloud.ply      kDefaultGroundTruthPoints points sampled on it, in G
// DIR/gt_mesh_before_slip.ply, gt_cloud_before_slip.ply
//                       with --slip-mm only: the same, as grasped
// DIR/claw.ply          the posed claw (palm + fingers) in G
// DIR/claw/claw.json    the claw as a description for `--claw` (+ meshes)
// DIR/scene.json        every parameter of the scene and what followed
//
// With --protocol paper it writes the paper's simulated test cloud instead
// (cmd_synth_protocol.cpp); synth_options.cpp parses the arguments of both
// modes, synth_json.cpp writes scene.json and claw/claw.json.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "claw_option.hpp"
#include "cmd_synth_grasps.hpp"
#include "cmd_synth_protocol.hpp"
#include "commands.hpp"
#include "data_paths.hpp"
#include "error_text.hpp"
#include "graspfill/io/atomic_file.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "number_parsing.hpp"
#include "object_mesh.hpp"
#include "output_dir.hpp"
#include "progress.hpp"
#include "sinks/lcm_log_writer.hpp"
#include "synth/renderer.hpp"
#include "synth/rig_errors.hpp"
#include "synth/scene.hpp"
#include "synth_json.hpp"
#include "synth_options.hpp"
#include "synth_recording.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// What the recording was made with: the claw exactly as rendered (the
// built-in with the dimensions the placement used, e.g. lengthened
// fingers), identity hand-eye (the poses are in the camera frame), no
// intrinsics override, and the pipeline's default workspace box and voxel
// (the recording does not ask for any other).
io::SessionDescription SessionOf(const synth::Scene& scene, int64_t utime, const SynthOptions& o) {
  io::SessionDescription session;
  session.utime = utime;
  session.software_version = io::SoftwareVersion();
  if (scene.config().claw_model) {
    DescribeFileClaw(o.claw, o.claw_mesh_root, *scene.config().claw_model, &session);
  } else {
    DescribeBuiltinClaw(synth::ClawTypeName(scene.config().claw), scene.placement().claw, &session);
  }
  return session;
}

// The scene the options describe; nullopt (said on stderr) when --mesh
// cannot be read or is too large to be in meters.
std::optional<synth::SceneConfig> SceneConfigOf(const SynthOptions& o) {
  synth::SceneConfig config;
  if (IsBuiltinClaw(o.claw)) {
    config.claw = *synth::ParseClawType(o.claw);
  } else {
    config.claw_model = std::make_shared<const claw::ClawModel>(MakeClaw(o.claw, o.claw_mesh_root));
  }
  config.grasp = *synth::ParseGraspWay(o.grasp);
  config.seed = o.seed;
  config.num_frames = o.frames;
  if (o.ideal) config.sensor = synth::SensorModelConfig::Ideal();
  config.sensor.mixed_pixel_prob = o.mixed_pixel_prob;
  config.sensor.projector_shadow = o.projector_shadow;
  config.sensor.dark_patch_share = o.dark_patch_share;
  config.sensor.depth_scale = o.depth_scale;
  config.sensor.intrinsics_scale = o.intrinsics_scale;
  config.sensor.wobble_m = 0.001 * o.wobble_mm;
  config.environment.wall_distance_m = o.wall_m;
  config.intrinsics = synth::IntrinsicsAtResolution(o.width, o.height);
  config.slip.distance_m = 0.001 * o.slip_mm;
  config.motion.speed_variation = o.speed_variation;
  if (o.shape) {
    config.shape = *synth::ParseShape(*o.shape);
    if (o.size) config.size_m = ParseSize(*o.size);
    return config;
  }
  try {
    config.mesh = ReadObjectMesh(*o.mesh_path, o.mesh_scale, o.mesh_y_up);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill synth: cannot read mesh: %s\n", ErrorText(e).c_str());
    return std::nullopt;
  }
  config.mesh_name = *o.mesh_path;
  const Eigen::Vector3d extent = mesh::Bounds(config.mesh).sizes();
  if (extent.maxCoeff() > kMaxObjectExtentM) {
    std::fprintf(stderr,
                 "graspfill synth: mesh '%s' is %.3g m across; graspfill expects meters "
                 "and objects a claw can hold (--mesh-scale 0.001 for a mesh in mm)\n",
                 o.mesh_path->c_str(), extent.maxCoeff());
    return std::nullopt;
  }
  return config;
}

// Every file a recording writes, the claw's link meshes included.
std::vector<std::string> RecordingOutputs(const claw::ClawModel& claw_model, bool slip) {
  std::vector<std::string> outputs = {"recording.lcmlog", "gt_mesh.ply", "gt_cloud.ply",
                                      "claw.ply",         "scene.json",  "claw/claw.json"};
  for (const claw::Link& link : claw_model.links()) outputs.push_back("claw/" + link.name + ".ply");
  if (slip) {
    outputs.push_back("gt_mesh_before_slip.ply");
    outputs.push_back("gt_cloud_before_slip.ply");
  }
  return outputs;
}

// The log: the session description, then the frames and the gripper
// states with the rig's errors. Returns the gripper states written.
size_t WriteRecording(const synth::Scene& scene, const SynthOptions& o, const synth::RigErrors& rig,
                      const io::ChannelNames& channels, const fs::path& log_path) {
  rt::LcmLogWriter log(log_path.string(), o.force);
  // The session description first, stamped with the first event's time
  // (so that lcm-logplayer does not wait before the recording starts).
  const std::vector<synth::TimelineEvent> timeline = scene.Timeline();
  const int64_t start_utime = timeline.empty() ? scene.config().motion.start_utime : timeline.front().utime;
  log.Write(channels.session, start_utime, io::EncodeSessionDescription(SessionOf(scene, start_utime, o)));
  ProgressLine progress("synth", "frames", scene.config().num_frames);
  int64_t frames_done = 0;
  const int64_t states = WriteSceneEvents(
      scene, timeline,
      [&](const synth::TimelineEvent& event) {
        // The rig's errors: the true pose at the robot's clock, then the
        // hand-eye error and this state's noise (identity by default).
        GripperState state = scene.GripperStateAt(rig.TrueUtime(event.utime));
        state.utime = event.utime;
        state.T_C_G = rig.Logged(state.T_C_G, event.index);
        return state;
      },
      channels, &log, &progress, &frames_done);
  log.Close();  // renamed into place only now, complete
  return static_cast<size_t>(states);
}

// The truth is where the object ends; with a slip, the same samples
// moved by the slide (point for point) beside the truth as grasped. Then
// the claw, posed and as a description.
void WriteTruthAndClaw(const synth::Scene& scene, const claw::ClawModel& claw_model, const fs::path& dir,
                       io::IfExists if_exists) {
  io::WriteMeshPly((dir / "gt_mesh.ply").string(), scene.object_G_after_slip(), if_exists);
  ObjectCloud gt = GroundTruthCloud(scene, scene.config().seed);
  if (scene.config().slip.any()) {
    io::WriteMeshPly((dir / "gt_mesh_before_slip.ply").string(), scene.object_G(), if_exists);
    io::WriteCloudPly((dir / "gt_cloud_before_slip.ply").string(), gt, if_exists);
    const Eigen::Vector3f d = scene.slip().Displacement_G().cast<float>();
    for (Eigen::Vector3f& p : gt.points_G) p += d;
  }
  io::WriteCloudPly((dir / "gt_cloud.ply").string(), gt, if_exists);
  io::WriteMeshPly((dir / "claw.ply").string(), scene.claw_G(), if_exists);
  WriteClawDescription(claw_model, dir / "claw", if_exists);
}

void PrintRecordingSummary(const synth::Scene& scene, const SynthOptions& o, const fs::path& log_path,
                           size_t gripper_states, int64_t log_bytes) {
  const Eigen::AlignedBox3d ws = scene.WorkspaceBoxG(0.02);
  std::printf(
      "wrote %s: %d depth frames + %zu gripper states (%lld bytes), opening %.4f m, "
      "workspace box in G [%.3f %.3f %.3f] .. [%.3f %.3f %.3f] m\n",
      log_path.string().c_str(), scene.config().num_frames, gripper_states, static_cast<long long>(log_bytes),
      scene.placement().opening_m, ws.min().x(), ws.min().y(), ws.min().z(), ws.max().x(), ws.max().y(),
      ws.max().z());
  if (scene.config().slip.any()) {
    std::printf("slip: %.2f mm along [%.3f %.3f %.3f] in G from utime %lld over %.2f s\n", o.slip_mm,
                scene.slip().direction_G().x(), scene.slip().direction_G().y(),
                scene.slip().direction_G().z(), static_cast<long long>(scene.slip().start_utime()),
                scene.config().slip.duration_s);
  }
}

int Run(const SynthOptions& o) {
  const std::optional<synth::SceneConfig> config = SceneConfigOf(o);
  if (!config) return 1;
  const fs::path dir(o.output_dir);
  // Every file this run writes, the claw's link meshes included, checked
  // (and refused without --force) before any frame is rendered.
  const synth::Scene scene(*config);
  const claw::ClawModel claw_model = scene.MakeClawModel();
  if (!PrepareOutputs(dir, RecordingOutputs(claw_model, config->slip.any()), o.force, "synth")) {
    return 1;
  }
  const synth::RigErrors rig(o.rig_errors, config->seed);
  const io::ChannelNames channels;
  const fs::path log_path = dir / "recording.lcmlog";
  const size_t gripper_states = WriteRecording(scene, o, rig, channels, log_path);
  const int64_t log_bytes = static_cast<int64_t>(fs::file_size(log_path));
  // Created only where nothing is (without --force): a file that appeared
  // since PrepareOutputs is not replaced.
  const io::IfExists if_exists = io::ReplaceIf(o.force);
  WriteTruthAndClaw(scene, claw_model, dir, if_exists);
  const json scene_json = SceneJson(scene, o, channels, log_bytes, gripper_states, rig);
  io::WriteFileAtomically((dir / "scene.json").string(), scene_json.dump(2) + "\n", "cannot write",
                          if_exists);
  PrintRecordingSummary(scene, o, log_path, gripper_states, log_bytes);
  return 0;
}

// The checked options of protocol mode, converted for cmd_synth_protocol.cpp.
SynthProtocolOptions ProtocolOptions(const SynthOptions& o) {
  SynthProtocolOptions p;
  p.shape = *synth::ParseShape(*o.shape);
  if (o.size) p.size_m = ParseSize(*o.size);
  p.grasp = *synth::ParseGraspWay(o.grasp);
  p.seed = o.seed;
  if (o.points) p.points = *o.points;
  p.force = o.force;
  p.output_dir = o.output_dir;
  return p;
}

}  // namespace

int RunSynth(const Args& args) {
  SynthOptions options;
  std::optional<SynthProtocolOptions> protocol_options;
  try {
    options = ParseSynthArgs(args);
    if (options.help) {
      std::fputs(kSynthUsage, stdout);
      return 0;
    }
    if (options.shape && !synth::ParseShape(*options.shape)) {
      throw UsageError("unknown shape '" + *options.shape + "'");
    }
    options.claw = ResolveClawSpec(options.claw, InstalledClawsDir());
    if (options.grasps && !IsBuiltinClaw(options.claw)) {
      throw UsageError("--grasps takes a built-in --claw (three-finger or parallel)");
    }
    if (!synth::ParseGraspWay(options.grasp)) {
      throw UsageError("unknown grasp '" + options.grasp + "'");
    }
    if (options.size) ParseSize(*options.size);
    if (options.protocol) protocol_options = ProtocolOptions(options);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "graspfill synth: %s\n%s", e.what(), kSynthUsage);
    return 2;
  }
  try {
    if (options.grasps) {
      SynthGraspsOptions g;
      g.shapes = ParseGraspShapes(*options.grasps);
      g.claw = options.claw;
      g.grasp = options.grasp;
      g.seed = options.seed;
      g.frames = options.frames;
      g.ideal = options.ideal;
      g.wall_m = options.wall_m;
      g.intrinsics = synth::IntrinsicsAtResolution(options.width, options.height);
      g.force = options.force;
      g.output_dir = options.output_dir;
      return RunSynthGrasps(g);
    }
    return protocol_options ? RunSynthProtocol(*protocol_options) : Run(options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill synth: error: %s\n", ErrorText(e).c_str());
    return 1;
  }
}

}  // namespace graspfill::cli
