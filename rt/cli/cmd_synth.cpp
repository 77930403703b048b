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
// (cmd_synth_protocol.cpp); this file parses the arguments of both modes.
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
#include "synth_recording.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kUsage =
    "usage: graspfill synth (--shape SHAPE [--size WxDxH] | --mesh FILE) -o DIR [options]\n"
    "       graspfill synth --protocol paper --shape SHAPE -o DIR [--size WxDxH]\n"
    "                       [--grasp WAY] [--seed N] [--points N] [--force]\n"
    "  --shape SHAPE     the paper's cuboid, triangular-prism, cylinder,\n"
    "                    sphere, elliptic-cylinder, ellipsoid, or the zoo's\n"
    "                    rounded-box, bottle, blob, mug (handle on +x), bowl\n"
    "  --size WxDxH      bounding box in meters, e.g. 0.07x0.07x0.14\n"
    "                    (default per shape; cuboid 0.07x0.07x0.14)\n"
    "  --mesh FILE       object mesh (.ply/.obj/.stl) in meters, +z up\n"
    "  --mesh-scale S    multiply the mesh's coordinates by S (0.001: a mesh in mm)\n"
    "  --mesh-up AXIS    z (default) or y: the mesh's up axis (y: many OBJ and\n"
    "                    glTF exports), turned onto +z\n"
    "  --claw SPEC       three-finger (default), parallel, or a claw file: a description\n"
    "                    (.json), a URDF or a URDF claw config (README \"Claws from URDF\"),\n"
    "                    or an installed description's name (robotiq_3f, franka_hand)\n"
    "  --claw-mesh-root DIR  where a claw file's meshes (and a config's URDF) are\n"
    "  --grasp WAY       top-straight (default), middle-straight, top-oblique\n"
    "  --grasps S1,S2,.. instead of --shape: one recording of several grasps in turn,\n"
    "                    grasp k holding shape k (gripper states with grasp_id k),\n"
    "                    --frames each; truth in DIR/grasp<k>/ (README \"Grasp after grasp\")\n"
    "  --seed N          sensor noise and wobble seed (default 1)\n"
    "  --frames N        depth frames at 30 Hz (default 90: one full turn)\n"
    "  --ideal           noise-free sensor (no noise, quantization, dropouts)\n"
    "  --wall-m D        background wall D m from the camera (default 1.4;\n"
    "                    0: none, which makes the log ~5x smaller)\n"
    "  --width W --height H  depth image size, 16..4096 (default 640 x 480), the\n"
    "                    same field of view (a 4096 x 4096 stream for the limits)\n"
    "  --hand-eye-error MM,DEG  logged poses off by a constant camera-frame error\n"
    "                    (MM mm in a random direction, DEG deg about a random axis)\n"
    "  --pose-noise MM,DEG  per gripper state noise in G (RMS), e.g. 0.5,0.2\n"
    "  --clock-offset-ms T  logged gripper stamps run T ms behind the frames\n"
    "                    (all three seeded, recorded in scene.json, off by default)\n"
    "  --speed-variation F  the turn's speed varies by F (0..0.9) of its mean, once\n"
    "                    over the recording (default 0: steady; a clock offset can\n"
    "                    only be told from a hand-eye error on a motion that varies)\n"
    "  --slip-mm S       the object slides S mm (0..20; 0: off, the default) in the\n"
    "                    grasp, along the fingers (within 15 deg of +z in G, away\n"
    "                    from the palm), starting at a seeded instant in 30-70 % of\n"
    "                    the recording, eased over 0.3 s; the claw stays. gt_mesh.ply\n"
    "                    and gt_cloud.ply are then the object after the slip, and\n"
    "                    gt_*_before_slip.ply as grasped (scene.json: slip)\n"
    "  --force           overwrite existing output files\n"
    "  -o, --output DIR  output folder (created if missing)\n"
    "writes DIR/recording.lcmlog, gt_mesh.ply, gt_cloud.ply, claw.ply,\n"
    "claw/claw.json and scene.json (geometry in the gripper frame G)\n"
    "\n"
    "--protocol paper: the simulated protocol of Cui et al. 2021, section 3.1,\n"
    "instead of a recording: a dense sample of the shape, the top cut off,\n"
    "three claw-sized holes dug out of the side, a random rigid pose\n"
    "  --grasp WAY       where the claw holes are (default top-straight)\n"
    "  --seed N          sample and pose seed (default 1)\n"
    "  --points N        points sampled on the whole surface, 1000..5000000\n"
    "                    (default 50000); the ground truth has as many\n"
    "writes DIR/holey.ply (the input to `graspfill repair`), gt_cloud.ply\n"
    "(ground truth, same pose) and protocol.json (pose, claw hole centres);\n"
    "--mesh, --claw, --frames, --ideal and --wall-m apply to recordings only\n"
    "example: graspfill synth --shape cylinder --claw parallel --seed 3 -o rec/\n";

struct SynthOptions {
  std::optional<std::string> protocol;
  std::optional<std::string> shape;
  std::optional<std::string> size;
  std::optional<std::string> mesh_path;
  double mesh_scale{1.0};     ///< --mesh-scale
  bool mesh_y_up{false};      ///< --mesh-up y
  bool mesh_transform_given{false};
  std::optional<std::string> grasps;  ///< --grasps S1,S2,...
  std::string claw{"three-finger"};
  std::string claw_mesh_root;  ///< --claw-mesh-root, for a claw file
  std::string grasp{"top-straight"};
  uint64_t seed{1};
  int frames{90};
  bool ideal{false};
  double wall_m{synth::EnvironmentConfig{}.wall_distance_m};
  bool force{false};
  std::string output_dir;
  bool help{false};
  std::optional<int> points;  ///< --protocol only
  synth::RigErrorConfig rig_errors;  ///< logged-pose errors (all off)
  double slip_mm{0.0};  ///< --slip-mm: the object's slide in the grasp (off)
  double speed_variation{0.0};  ///< --speed-variation (steady turn)
  int width{CameraIntrinsics{}.width};    ///< depth image size [pixels]
  int height{CameraIntrinsics{}.height};
  /// Options given that only a recording uses, to refuse them in protocol
  /// mode rather than silently ignore them.
  std::vector<std::string> recording_only_given;
};

Eigen::Vector3d ParseSize(const std::string& text) {
  Eigen::Vector3d size;
  std::stringstream in(text);
  for (int k = 0; k < 3; ++k) {
    std::string part;
    if (!std::getline(in, part, 'x') || part.empty()) {
      throw UsageError("--size '" + text + "': expected WxDxH, e.g. 0.07x0.07x0.14");
    }
    try {
      size[k] = ParseDouble("--size", part, 0.0, std::numeric_limits<double>::max(), "m");
    } catch (const UsageError&) {
      size[k] = 0.0;
    }
    if (!(size[k] > 0.0)) {
      throw UsageError("--size '" + text + "': '" + part + "' is not a positive number");
    }
  }
  std::string rest;
  if (std::getline(in, rest)) throw UsageError("--size '" + text + "': expected 3 values");
  if (size.maxCoeff() > 1.0) {
    throw UsageError("--size '" + text + "': sizes are in meters (e.g. 0.07 for 7 cm)");
  }
  return size;
}

// "MM,DEG" of --hand-eye-error / --pose-noise, into meters and degrees.
void ParseMmDeg(const std::string& option, const std::string& text, double* m, double* deg) {
  const size_t comma = text.find(',');
  if (comma == std::string::npos) {
    throw UsageError(option + " '" + text + "': expected MM,DEG, e.g. 3,1");
  }
  *m = 0.001 * ParseDouble(option, text.substr(0, comma), 0.0, 50.0, "mm");
  *deg = ParseDouble(option, text.substr(comma + 1), 0.0, 10.0, "deg");
}

// Options of recordings only, refused with --protocol paper.
bool IsRecordingOnly(const std::string& a) {
  return a == "--mesh" || a == "--mesh-scale" || a == "--mesh-up" || a == "--claw" ||
         a == "--frames" || a == "--ideal" || a == "--wall-m" || a == "--hand-eye-error" ||
         a == "--pose-noise" || a == "--clock-offset-ms" || a == "--width" || a == "--height" ||
         a == "--slip-mm" || a == "--speed-variation";
}

// args[*i] (and its value, advancing *i) into *o.
// @throws UsageError on an unknown option, a missing or bad value.
void ParseOption(const Args& args, size_t* i, SynthOptions* o) {
  const std::string& a = args[*i];
  auto value = [&]() -> std::string {
    if (*i + 1 >= args.size()) throw UsageError(a + " needs a value");
    return args[++*i];
  };
  if (IsRecordingOnly(a)) o->recording_only_given.push_back(a);
  if (a == "-h" || a == "--help") o->help = true;
  else if (a == "--protocol") o->protocol = value();
  else if (a == "--shape") o->shape = value();
  else if (a == "--size") o->size = value();
  else if (a == "--mesh") o->mesh_path = value();
  else if (a == "--mesh-scale") {
    o->mesh_scale = ParseDouble(a, value(), 1e-6, 1e6, "");
    o->mesh_transform_given = true;
  } else if (a == "--mesh-up") {
    o->mesh_transform_given = true;
    const std::string axis = value();
    if (axis != "y" && axis != "z") throw UsageError("--mesh-up must be y or z, not '" + axis + "'");
    o->mesh_y_up = axis == "y";
  }
  else if (a == "--grasps") o->grasps = value();
  else if (a == "--claw") o->claw = value();
  else if (a == "--claw-mesh-root") {
    o->recording_only_given.push_back(a);
    o->claw_mesh_root = value();
  }
  else if (a == "--grasp") o->grasp = value();
  else if (a == "--seed") {
    o->seed = ParseInteger<uint64_t>(a, value(), 0, std::numeric_limits<uint64_t>::max());
  } else if (a == "--frames") o->frames = ParseInteger<int>(a, value(), 1, 100000);
  else if (a == "--ideal") o->ideal = true;
  else if (a == "--wall-m") o->wall_m = ParseDouble(a, value(), 0.0, 100.0, "m");
  else if (a == "--points") {
    o->points = ParseInteger<int>(a, value(), kMinProtocolPoints, kMaxProtocolPoints);
  }
  else if (a == "--hand-eye-error") {
    ParseMmDeg(a, value(), &o->rig_errors.hand_eye_m, &o->rig_errors.hand_eye_deg);
  } else if (a == "--pose-noise") {
    ParseMmDeg(a, value(), &o->rig_errors.pose_noise_m, &o->rig_errors.pose_noise_deg);
  } else if (a == "--clock-offset-ms") {
    o->rig_errors.clock_offset_us = std::llround(1000.0 * ParseDouble(a, value(), -90.0, 90.0, "ms"));
  }
  else if (a == "--slip-mm") o->slip_mm = ParseDouble(a, value(), 0.0, 20.0, "mm");
  else if (a == "--speed-variation") o->speed_variation = ParseDouble(a, value(), 0.0, 0.9, "");
  else if (a == "--width") o->width = ParseInteger<int>(a, value(), 16, 4096);
  else if (a == "--height") o->height = ParseInteger<int>(a, value(), 16, 4096);
  else if (a == "--force") o->force = true;
  else if (a == "-o" || a == "--output") o->output_dir = value();
  else throw BadOption(a, kUsage);
}

// The options that go together: --protocol paper with a shape and nothing
// of recordings, --grasps instead of --shape, one of --shape and --mesh.
// @throws UsageError
void CheckCombination(const SynthOptions& o) {
  if (o.protocol) {
    if (*o.protocol != "paper") {
      throw UsageError("unknown --protocol '" + *o.protocol + "' (the only one is 'paper')");
    }
    if (!o.recording_only_given.empty()) {
      throw UsageError(o.recording_only_given.front() +
                       " applies to recordings only, not to --protocol paper");
    }
    if (!o.shape) throw UsageError("--protocol paper needs --shape");
  } else if (o.points) {
    throw UsageError("--points applies to --protocol paper only");
  }
  if (o.grasps) {
    if (o.protocol || o.shape || o.mesh_path || o.size) {
      throw UsageError("--grasps replaces --shape (no --mesh, --size, --protocol)");
    }
    if (o.slip_mm != 0.0) throw UsageError("--slip-mm applies to one grasp, not to --grasps");
    // Not silently dropped: the grasps' scenes take neither.
    if (o.rig_errors.any()) {
      throw UsageError("--hand-eye-error, --pose-noise and --clock-offset-ms apply to one grasp, "
                       "not to --grasps");
    }
    if (o.speed_variation != 0.0) throw UsageError("--speed-variation applies to one grasp, not to --grasps");
    ParseGraspShapes(*o.grasps);
  } else if (o.shape.has_value() == o.mesh_path.has_value()) {
    throw UsageError("give exactly one of --shape and --mesh");
  }
  if (o.mesh_path && o.size) throw UsageError("--size applies to --shape only");
  if (!o.mesh_path && o.mesh_transform_given) {
    throw UsageError("--mesh-scale and --mesh-up apply to --mesh only");
  }
  if (o.output_dir.empty()) throw UsageError("missing -o DIR");
}

SynthOptions Parse(const Args& args) {
  SynthOptions o;
  for (size_t i = 0; i < args.size(); ++i) ParseOption(args, &i, &o);
  if (!o.help) CheckCombination(o);
  return o;
}

json Vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

json Matrix(const Eigen::Isometry3d& T) {
  json rows = json::array();
  for (int r = 0; r < 4; ++r) {
    rows.push_back(json::array({T(r, 0), T(r, 1), T(r, 2), T(r, 3)}));
  }
  return rows;
}

json ClawJson(const claw::ProceduralClawConfig& c) {
  return {{"palm_radius_m", c.palm_radius_m},
          {"palm_thickness_m", c.palm_thickness_m},
          {"finger_length_m", c.finger_length_m},
          {"finger_width_m", c.finger_width_m},
          {"finger_thickness_m", c.finger_thickness_m},
          {"min_opening_m", c.min_opening_m},
          {"max_opening_m", c.max_opening_m}};
}

json Pose(const Eigen::Isometry3d& T) {
  // URDF rpy: R = Rz(yaw) * Ry(pitch) * Rx(roll).
  const Eigen::Vector3d ypr = T.linear().eulerAngles(2, 1, 0);
  return {{"xyz", Vec(T.translation())}, {"rpy", Vec(Eigen::Vector3d(ypr[2], ypr[1], ypr[0]))}};
}

// The claw model as a description file (config/claws/README.md) with one
// PLY per link beside it, so `--claw DIR/claw/claw.json` replays with the
// exact claw, including lengthened fingers.
void WriteClawDescription(const claw::ClawModel& model, const fs::path& dir, io::IfExists if_exists) {
  fs::create_directories(dir);
  json links = json::array();
  for (const claw::Link& link : model.links()) {
    const std::string mesh_file = link.name + ".ply";
    io::WriteMeshPly((dir / mesh_file).string(), link.mesh, if_exists);
    json j = {{"name", link.name}, {"mesh", mesh_file}, {"mesh_origin", Pose(link.T_link_mesh)}};
    if (link.parent >= 0) j["parent"] = model.links()[link.parent].name;
    if (link.joint.type != claw::JointType::kFixed) {
      j["joint"] = {
          {"type", link.joint.type == claw::JointType::kPrismatic ? "prismatic" : "revolute"},
          {"origin", Pose(link.joint.T_parent_joint)},
          {"axis", Vec(link.joint.axis)},
          {"limits", {{"lower", link.joint.lower}, {"upper", link.joint.upper}}},
          {"drive", {{"opening_gain", link.joint.gain}, {"opening_offset", link.joint.offset}}}};
      if (link.joint.joint_index >= 0) j["joint"]["drive"]["joint_index"] = link.joint.joint_index;
    } else {  // a root's too: a description or URDF claw's root is placed in G
      j["joint"] = {{"type", "fixed"}, {"origin", Pose(link.joint.T_parent_joint)}};
    }
    links.push_back(j);
  }
  const json description = {
      {"name", model.name()},
      {"opening_doc", "radius of the fingers' inner faces from G's z axis [m]"},
      {"links", links}};
  io::WriteFileAtomically((dir / "claw.json").string(), description.dump(2) + "\n", "cannot write",
                          if_exists);
}

json RigErrorsJson(const synth::RigErrors& rig) {
  const synth::RigErrorConfig& c = rig.config();
  const Eigen::AngleAxisd error(rig.hand_eye_error().linear());
  return {{"doc", "a state stamped t logs E_C * T_C_G_true(t + clock_offset) * N_k; frames and "
                  "ground truth in the true G"},
          {"hand_eye_error_m", c.hand_eye_m},
          {"hand_eye_error_deg", c.hand_eye_deg},
          {"E_C", Matrix(rig.hand_eye_error())},
          {"E_C_angle_deg", error.angle() * 180.0 / 3.14159265358979323846},
          {"pose_noise_rms_m", c.pose_noise_m},
          {"pose_noise_rms_deg", c.pose_noise_deg},
          {"clock_offset_us", c.clock_offset_us}};
}

json SlipJson(const synth::Scene& scene) {
  const synth::ObjectSlip& slip = scene.slip();
  const synth::SlipConfig& c = slip.config();
  // The first depth frame that sees any of the slide, and the first that
  // sees all of it.
  int first_moved = scene.num_frames(), first_settled = scene.num_frames();
  for (int i = scene.num_frames() - 1; i >= 0; --i) {
    const double progress = slip.Progress(scene.DepthUtime(i));
    if (progress > 0.0) first_moved = i;
    if (progress >= 1.0) first_settled = i;
  }
  return {{"doc", "the object slides by displacement_G_m = distance_m * direction_G (in G) "
                  "relative to the claw, smoothstep-eased from start_utime over duration_s; "
                  "the claw and the gripper states do not move; gt_mesh.ply and gt_cloud.ply "
                  "hold the object after the slip, gt_*_before_slip.ply before it"},
          {"distance_mm", 1000.0 * c.distance_m},
          {"distance_m", c.distance_m},
          {"direction_G", Vec(slip.direction_G())},
          {"displacement_G_m", Vec(slip.Displacement_G())},
          {"max_tilt_deg", c.max_tilt_deg},
          {"start_fraction_range", json::array({c.start_min_fraction, c.start_max_fraction})},
          {"start_utime", slip.start_utime()},
          {"end_utime", slip.end_utime()},
          {"duration_s", c.duration_s},
          {"first_frame_moved", first_moved},
          {"first_frame_settled", first_settled},
          {"mesh_before_slip", "gt_mesh_before_slip.ply"},
          {"cloud_before_slip", "gt_cloud_before_slip.ply"}};
}

json ObjectJson(const synth::Scene& scene, const SynthOptions& o) {
  const synth::SceneConfig& c = scene.config();
  json object = {{"size_m", Vec(mesh::Bounds(scene.object_O()).sizes())}};
  if (o.mesh_path) {
    object["source"] = "mesh";
    object["mesh_path"] = fs::absolute(*o.mesh_path).string();
    object["mesh_scale"] = o.mesh_scale;
    object["mesh_up"] = o.mesh_y_up ? "y" : "z";
  } else {
    object["source"] = "shape";
    object["shape"] = synth::ShapeName(c.shape);
    object["size_m"] = Vec(c.EffectiveSize());
    object["segments"] = c.shape_segments;
  }
  return object;
}

json SensorJson(const synth::SensorModelConfig& s, bool ideal) {
  return {{"ideal", ideal},
          {"noise", s.noise},
          {"sigma_base_m", s.sigma_base_m},
          {"sigma_quadratic_m", s.sigma_quadratic_m},
          {"sigma_reference_depth_m", s.sigma_reference_depth_m},
          {"sigma_angular_m", s.sigma_angular_m},
          {"quantize", s.quantize},
          {"baseline_m", s.baseline_m},
          {"disparity_steps_per_px", s.disparity_steps_per_px},
          {"min_range_m", s.min_range_m},
          {"max_range_m", s.max_range_m},
          {"grazing_start_deg", s.grazing_start_deg},
          {"grazing_full_deg", s.grazing_full_deg},
          {"edge_jump_m", s.edge_jump_m},
          {"edge_dropout_prob", s.edge_dropout_prob},
          {"random_dropout_prob", s.random_dropout_prob},
          {"model_doc", "Nguyen et al. 2012 axial noise, 1/8 px disparity "
                        "quantization, grazing/edge/random dropouts"}};
}

// The placement's config and what it gave.
json PlacementJson(const synth::PlacementConfig& c, const synth::Placement& p) {
  return {{"min_palm_gap_m", c.min_palm_gap_m},
          {"top_contact_fraction", c.top_contact_fraction},
          {"middle_contact_fraction", c.middle_contact_fraction},
          {"finger_pad_m", c.finger_pad_m},
          {"oblique_tilt_deg", c.oblique_tilt_deg},
          {"finger_clearance_m", c.finger_clearance_m},
          {"T_G_O", Matrix(p.T_G_O)},
          {"palm_gap_m", p.palm_gap_m},
          {"contact_fraction", p.contact_fraction},
          {"opening_m", p.opening_m},
          {"finger_touch_radius_m", p.finger_touch_radius_m}};
}

json MotionJson(const synth::Scene& scene) {
  const synth::MotionConfig& m = scene.config().motion;
  return {{"camera_distance_m", m.camera_distance_m},
          {"camera_elevation_deg", m.camera_elevation_deg},
          {"turns", m.turns},
          {"wobble_deg", m.wobble_deg},
          {"wobble_translation_m", m.wobble_translation_m},
          {"start_utime", m.start_utime},
          {"T_W_C", Matrix(scene.T_W_C())},
          {"T_C_G_first_frame", Matrix(scene.T_C_G(0.0))}};
}

json LogJson(const synth::Scene& scene, const io::ChannelNames& ch, int64_t log_bytes,
             size_t gripper_states) {
  const int num_frames = scene.config().num_frames;
  return {{"file", "recording.lcmlog"},
          {"bytes", log_bytes},
          {"depth_channel", ch.depth},
          {"gripper_state_channel", ch.gripper_state},
          {"depth_encoding", "zlib16"},
          {"depth_scale_m", 0.001},
          {"depth_frames", num_frames},
          {"gripper_states", gripper_states},
          {"first_depth_utime", scene.DepthUtime(0)},
          {"last_depth_utime", scene.DepthUtime(num_frames - 1)}};
}

json SceneJson(const synth::Scene& scene, const SynthOptions& o, const io::ChannelNames& ch,
               int64_t log_bytes, size_t gripper_states, const synth::RigErrors& rig) {
  const synth::SceneConfig& c = scene.config();
  const synth::Placement& p = scene.placement();
  const Eigen::AlignedBox3d workspace = scene.WorkspaceBoxG(0.02);
  json j = {
      {"format", "graspfill-synth-scene/1"},
      {"software_version", io::SoftwareVersion()},
      {"frames_doc", "geometry in the gripper frame G (origin palm face centre, +z approach); "
                     "T_A_B maps points from B to A; meters, microseconds"},
      {"object", ObjectJson(scene, o)},
      {"claw", {{"type", c.claw_model ? c.claw_model->name() : synth::ClawTypeName(c.claw)},
                {"config", ClawJson(c.claw_config)},
                {"used", ClawJson(p.claw)},
                {"description", "claw/claw.json"}}},
      {"grasp", synth::GraspWayName(c.grasp)},
      {"seed", c.seed},
      {"num_frames", c.num_frames},
      {"depth_rate_hz", c.depth_rate_hz},
      {"gripper_rate_hz", c.gripper_rate_hz},
      {"gripper_offset_us", c.gripper_offset_us},
      {"gripper_lead_s", c.gripper_lead_s},
      {"intrinsics", {{"width", c.intrinsics.width}, {"height", c.intrinsics.height},
                      {"fx", c.intrinsics.fx}, {"fy", c.intrinsics.fy},
                      {"cx", c.intrinsics.cx}, {"cy", c.intrinsics.cy}}},
      {"sensor", SensorJson(c.sensor, o.ideal)},
      {"placement", PlacementJson(c.placement, p)},
      {"motion", MotionJson(scene)},
      {"environment", {{"wall_distance_m", c.environment.wall_distance_m},
                       {"arm_radius_m", c.environment.arm_radius_m},
                       {"arm_length_m", c.environment.arm_length_m}}},
      {"workspace_box_G", {{"min", Vec(workspace.min())}, {"max", Vec(workspace.max())},
                           {"doc", "object bounding box in G grown by 2 cm, cut at the "
                                   "palm face z = 0"}}},
      {"log", LogJson(scene, ch, log_bytes, gripper_states)},
      {"rig_errors", RigErrorsJson(rig)},
      {"ground_truth", {{"mesh", "gt_mesh.ply"},
                        {"cloud", "gt_cloud.ply"},
                        {"cloud_points", synth::kDefaultGroundTruthPoints},
                        {"cloud_seed", c.seed},
                        {"claw_mesh", "claw.ply"}}},
  };
  // Only with a slip: without one scene.json stays as it was.
  if (c.slip.any()) j["slip"] = SlipJson(scene);
  if (c.motion.speed_variation != 0.0) j["motion"]["speed_variation"] = c.motion.speed_variation;
  return j;
}

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
                                      "claw.ply", "scene.json", "claw/claw.json"};
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
  const int64_t start_utime =
      timeline.empty() ? scene.config().motion.start_utime : timeline.front().utime;
  log.Write(channels.session, start_utime,
            io::EncodeSessionDescription(SessionOf(scene, start_utime, o)));
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
void WriteTruthAndClaw(const synth::Scene& scene, const claw::ClawModel& claw_model,
                       const fs::path& dir, io::IfExists if_exists) {
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

void PrintRecordingSummary(const synth::Scene& scene, const SynthOptions& o,
                           const fs::path& log_path, size_t gripper_states, int64_t log_bytes) {
  const Eigen::AlignedBox3d ws = scene.WorkspaceBoxG(0.02);
  std::printf(
      "wrote %s: %d depth frames + %zu gripper states (%lld bytes), opening %.4f m, "
      "workspace box in G [%.3f %.3f %.3f] .. [%.3f %.3f %.3f] m\n",
      log_path.string().c_str(), scene.config().num_frames, gripper_states,
      static_cast<long long>(log_bytes), scene.placement().opening_m, ws.min().x(),
      ws.min().y(), ws.min().z(), ws.max().x(), ws.max().y(), ws.max().z());
  if (scene.config().slip.any()) {
    std::printf("slip: %.2f mm along [%.3f %.3f %.3f] in G from utime %lld over %.2f s\n",
                o.slip_mm, scene.slip().direction_G().x(), scene.slip().direction_G().y(),
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
    options = Parse(args);
    if (options.help) {
      std::fputs(kUsage, stdout);
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
    std::fprintf(stderr, "graspfill synth: %s\n%s", e.what(), kUsage);
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
