// SPDX-License-Identifier: BSD-3-Clause
#include "synth_options.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include "cmd_synth_grasps.hpp"
#include "cmd_synth_protocol.hpp"
#include "number_parsing.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {

const char* const kSynthUsage =
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
    "  --mixed-pixels P  a pixel on a depth edge returns a depth between the edge's\n"
    "                    two sides with probability P (0..1; default 0: a Kinect v1\n"
    "                    loses its edges instead), the flying pixels of ToF cameras\n"
    "  --projector-shadow  no depth where the projector, 75 mm beside the camera\n"
    "                    (+x), cannot light the surface: the bands beside fingers\n"
    "  --dark-patches F  a share F (0..0.5) of the object's surface lies in dark or\n"
    "                    shiny patches ~1 cm across that return nothing, fixed on\n"
    "                    the object as it turns (default 0)\n"
    "  --depth-scale S   every depth comes out S times its truth (0.9..1.1; 1.01: 1%\n"
    "                    long, an uncalibrated sensor; default 1)\n"
    "  --intrinsics-scale S  the frames state fx and fy S times the true ones\n"
    "                    (0.9..1.1; default 1)\n"
    "  --wobble-mm A     a slow depth offset of whole frames, A sin(2 pi t / 2 s)\n"
    "                    (0..5 mm; default 0; all three recorded in scene.json)\n"
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

namespace {

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
  return a == "--mesh" || a == "--mesh-scale" || a == "--mesh-up" || a == "--claw" || a == "--frames" ||
         a == "--ideal" || a == "--wall-m" || a == "--hand-eye-error" || a == "--pose-noise" ||
         a == "--clock-offset-ms" || a == "--width" || a == "--height" || a == "--slip-mm" ||
         a == "--speed-variation" || a == "--mixed-pixels" || a == "--depth-scale" ||
         a == "--intrinsics-scale" || a == "--wobble-mm" || a == "--projector-shadow" ||
         a == "--dark-patches";
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
  if (a == "-h" || a == "--help")
    o->help = true;
  else if (a == "--protocol")
    o->protocol = value();
  else if (a == "--shape")
    o->shape = value();
  else if (a == "--size")
    o->size = value();
  else if (a == "--mesh")
    o->mesh_path = value();
  else if (a == "--mesh-scale") {
    o->mesh_scale = ParseDouble(a, value(), 1e-6, 1e6, "");
    o->mesh_transform_given = true;
  } else if (a == "--mesh-up") {
    o->mesh_transform_given = true;
    const std::string axis = value();
    if (axis != "y" && axis != "z") throw UsageError("--mesh-up must be y or z, not '" + axis + "'");
    o->mesh_y_up = axis == "y";
  } else if (a == "--grasps")
    o->grasps = value();
  else if (a == "--claw")
    o->claw = value();
  else if (a == "--claw-mesh-root") {
    o->recording_only_given.push_back(a);
    o->claw_mesh_root = value();
  } else if (a == "--grasp")
    o->grasp = value();
  else if (a == "--seed") {
    o->seed = ParseInteger<uint64_t>(a, value(), 0, std::numeric_limits<uint64_t>::max());
  } else if (a == "--frames")
    o->frames = ParseInteger<int>(a, value(), 1, 100000);
  else if (a == "--ideal")
    o->ideal = true;
  else if (a == "--wall-m")
    o->wall_m = ParseDouble(a, value(), 0.0, 100.0, "m");
  else if (a == "--points") {
    o->points = ParseInteger<int>(a, value(), kMinProtocolPoints, kMaxProtocolPoints);
  } else if (a == "--hand-eye-error") {
    ParseMmDeg(a, value(), &o->rig_errors.hand_eye_m, &o->rig_errors.hand_eye_deg);
  } else if (a == "--pose-noise") {
    ParseMmDeg(a, value(), &o->rig_errors.pose_noise_m, &o->rig_errors.pose_noise_deg);
  } else if (a == "--clock-offset-ms") {
    o->rig_errors.clock_offset_us = std::llround(1000.0 * ParseDouble(a, value(), -90.0, 90.0, "ms"));
  } else if (a == "--slip-mm")
    o->slip_mm = ParseDouble(a, value(), 0.0, 20.0, "mm");
  else if (a == "--speed-variation")
    o->speed_variation = ParseDouble(a, value(), 0.0, 0.9, "");
  else if (a == "--mixed-pixels")
    o->mixed_pixel_prob = ParseDouble(a, value(), 0.0, 1.0, "");
  else if (a == "--projector-shadow")
    o->projector_shadow = true;
  else if (a == "--dark-patches")
    o->dark_patch_share = ParseDouble(a, value(), 0.0, 0.5, "");
  else if (a == "--depth-scale")
    o->depth_scale = ParseDouble(a, value(), 0.9, 1.1, "");
  else if (a == "--intrinsics-scale")
    o->intrinsics_scale = ParseDouble(a, value(), 0.9, 1.1, "");
  else if (a == "--wobble-mm")
    o->wobble_mm = ParseDouble(a, value(), 0.0, 5.0, "mm");
  else if (a == "--width")
    o->width = ParseInteger<int>(a, value(), 16, 4096);
  else if (a == "--height")
    o->height = ParseInteger<int>(a, value(), 16, 4096);
  else if (a == "--force")
    o->force = true;
  else if (a == "-o" || a == "--output")
    o->output_dir = value();
  else
    throw BadOption(a, kSynthUsage);
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
      throw UsageError(
          "--hand-eye-error, --pose-noise and --clock-offset-ms apply to one grasp, "
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

}  // namespace

SynthOptions ParseSynthArgs(const Args& args) {
  SynthOptions o;
  for (size_t i = 0; i < args.size(); ++i) ParseOption(args, &i, &o);
  if (!o.help) CheckCombination(o);
  return o;
}

}  // namespace graspfill::cli
