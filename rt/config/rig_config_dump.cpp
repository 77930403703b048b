// SPDX-License-Identifier: BSD-3-Clause
// DumpRigConfig: the rig config as YAML, every field under its comment.
#include <yaml-cpp/yaml.h>

#include <array>
#include <sstream>

#include "config/rig_config.hpp"
#include "config/rig_config_checks.hpp"
#include "graspfill/fusion/tsdf_fusion.hpp"

namespace graspfill::rt {

using namespace internal;  // the ranges and checks (rig_config_checks.hpp)

namespace {

std::string Quoted(const std::string& s) {
  YAML::Emitter e;
  e << YAML::DoubleQuoted << s;
  return e.c_str();
}

template <size_t N>
std::string List(const std::array<double, N>& v) {
  std::string out = "[";
  for (size_t k = 0; k < N; ++k) out += (k ? ", " : "") + FormatNumber(v[k]);
  return out + "]";
}

const char* Bool(bool b) { return b ? "true" : "false"; }

// Lines of YAML with comments above their keys.
class Writer {
 public:
  void Comment(int indent, const std::string& text) {
    out_ << std::string(2 * indent, ' ') << "# " << text << "\n";
  }
  void Key(int indent, const std::string& key, const std::string& value) {
    out_ << std::string(2 * indent, ' ') << key << ":" << (value.empty() ? "" : " " + value) << "\n";
  }
  void Blank() { out_ << "\n"; }
  std::string str() const { return out_.str(); }

 private:
  std::ostringstream out_;
};

void WritePose(Writer* w, int indent, const RigConfig::Pose& p) {
  w->Key(indent, "translation_m", List(p.translation_m));
  w->Key(indent, "rotation_wxyz", List(p.rotation_wxyz));
}

void WriteBox(Writer* w, int indent, const RigConfig::Box& b) {
  w->Key(indent, "min_G_m", List(b.min_G_m));
  w->Key(indent, "max_G_m", List(b.max_G_m));
}

void WriteIntrinsics(Writer* w, int indent, const RigConfig::Intrinsics& K) {
  w->Key(indent, "width_px", std::to_string(K.width_px));
  w->Key(indent, "height_px", std::to_string(K.height_px));
  w->Key(indent, "fx_px", FormatNumber(K.fx_px));
  w->Key(indent, "fy_px", FormatNumber(K.fy_px));
  w->Key(indent, "cx_px", FormatNumber(K.cx_px));
  w->Key(indent, "cy_px", FormatNumber(K.cy_px));
}

// The camera: the device, its video mode, the intrinsics override, the depth size limit.
void DumpCamera(Writer* w, const RigConfig& c, const RigConfig& d) {
  w->Key(0, "camera", "");
  w->Comment(1, "OpenNI2 device URI, an .oni file or graspfill-replay:LOG; \"\" = any device (live).");
  w->Key(1, "device", Quoted(c.camera.device));
  w->Comment(1, "Video mode asked of the device (live); 0 = the device's own.");
  w->Key(1, "width_px", std::to_string(c.camera.width_px));
  w->Key(1, "height_px", std::to_string(c.camera.height_px));
  w->Key(1, "fps", std::to_string(c.camera.fps));
  w->Comment(1, "Depth units asked of the device: mm or 100um.");
  w->Key(1, "depth_units", c.camera.depth_units);
  w->Comment(1, "Pinhole intrinsics instead of the depth images' own, for images of");
  w->Comment(1, "width_px x height_px (an OpenNI2 device: fx, fy, cx, cy replace its own); all");
  w->Comment(1, "six keys. null: the session description's override, else the images' own. E.g.:");
  {
    Writer example;
    WriteIntrinsics(&example, 0, RigConfig::Intrinsics{});
    std::istringstream lines(example.str());
    std::string line;
    w->Comment(1, "intrinsics_override:");
    while (std::getline(lines, line)) w->Comment(1, "  " + line);
  }
  if (c.camera.intrinsics_override) {
    w->Key(1, "intrinsics_override", "");
    WriteIntrinsics(w, 2, *c.camera.intrinsics_override);
  } else {
    w->Key(1, "intrinsics_override", "null");
  }
  w->Comment(1, "Depth images (bus, log) with more pixels are refused before they are decoded,");
  w->Comment(1, "counted as bad_size; 1.." + std::to_string(io::kMaxDepthPixels) + " (default " +
                    std::to_string(d.camera.max_depth_pixels) + " = 8 MP: the largest common");
  w->Comment(
      1, "depth sensors are ~5 MP; a 4096 x 4096 stream needs " + std::to_string(io::kMaxDepthPixels) + ").");
  w->Key(1, "max_depth_pixels", std::to_string(c.camera.max_depth_pixels));
  w->Comment(1, "Drop the pixels on depth edges before fusion: mixed (flying) pixels and the");
  w->Comment(1, "silhouette's grazing returns (default false: measured in");
  w->Comment(1, "docs/measurements/2026-12-06-depth-edges.md).");
  w->Key(1, "reject_depth_edges", c.camera.reject_depth_edges ? "true" : "false");
  w->Comment(1, "The sensor's depth is this many times the true one (as a replay reported in");
  w->Comment(1, "refine.depth_scale.factor): frames are divided by it from the first; 0.8..1.25.");
  w->Key(1, "depth_scale", FormatNumber(c.camera.depth_scale));
}

// The robot: hand-eye, clock offset, pose gap.
void DumpRobot(Writer* w, const RigConfig& c, const RigConfig& d) {
  w->Key(0, "robot", "");
  w->Comment(1, "Hand-eye calibration T_C_B: maps points from the robot base B to the camera C");
  w->Comment(1, "(p_C = R * p_B + t), for gripper states sent in the base frame; both keys.");
  w->Comment(1, "null: the session description's, else identity:");
  w->Comment(1, "T_C_B: {translation_m: " + List(RigConfig::Pose{}.translation_m) +
                    ", rotation_wxyz: " + List(RigConfig::Pose{}.rotation_wxyz) + "}");
  if (c.robot.T_C_B) {
    w->Key(1, "T_C_B", "");
    WritePose(w, 2, *c.robot.T_C_B);
  } else {
    w->Key(1, "T_C_B", "null");
  }
  w->Comment(1, "Added to every gripper state's stamp: the robot's clock onto the camera's [s]");
  w->Comment(1, "(default " + FormatNumber(d.robot.clock_offset_s) + ").");
  w->Key(1, "clock_offset_s", FormatNumber(c.robot.clock_offset_s));
  w->Comment(1, "A depth frame is fused only between gripper states at most this far apart [s]");
  w->Comment(1, "(default " + FormatNumber(d.robot.max_pose_gap_s) + ").");
  w->Key(1, "max_pose_gap_s", FormatNumber(c.robot.max_pose_gap_s));
}

// The claw: its spec and mesh root.
void DumpClaw(Writer* w, const RigConfig& c) {
  w->Key(0, "claw", "");
  w->Comment(1, "three-finger, parallel, a claw description .json, a .urdf or a URDF config");
  w->Comment(1, ".json; \"\" = the session description's claw, else three-finger.");
  w->Key(1, "spec", Quoted(c.claw.spec));
  w->Comment(1, "Where a description's or URDF's meshes are; \"\" = beside it.");
  w->Key(1, "mesh_root", Quoted(c.claw.mesh_root));
}

// The workspace: the object's box (null: the session description's).
void DumpWorkspace(Writer* w, const RigConfig& c) {
  w->Comment(0, "The object's box in the gripper frame G [m] (crops each depth frame); both keys.");
  w->Comment(0, "null: the session description's, else:");
  {
    const RigConfig::Box b;
    w->Comment(0, "workspace: {min_G_m: " + List(b.min_G_m) + ", max_G_m: " + List(b.max_G_m) + "}");
  }
  if (c.workspace) {
    w->Key(0, "workspace", "");
    WriteBox(w, 1, *c.workspace);
  } else {
    w->Key(0, "workspace", "null");
  }
}

// The tsdf: the fusion's voxel and sampling.
void DumpTsdf(Writer* w, const RigConfig& c, const RigConfig& d) {
  w->Key(0, "tsdf", "");
  w->Comment(1, "Voxel edge [m], " + FormatNumber(kVoxelM.min) + ".." + FormatNumber(kVoxelM.max) +
                    "; null: the session description's, else " + FormatNumber(fusion::TsdfConfig{}.voxel_m) +
                    ".");
  w->Key(1, "voxel_m", c.tsdf.voxel_m ? FormatNumber(*c.tsdf.voxel_m) : "null");
  w->Comment(1, "Truncation distance in voxels (default " + FormatNumber(d.tsdf.sdf_trunc_voxels) + ").");
  w->Key(1, "sdf_trunc_voxels", FormatNumber(c.tsdf.sdf_trunc_voxels));
  w->Comment(1,
             "Open3D's voxel block edge [voxels] (default " + std::to_string(d.tsdf.block_resolution) + ").");
  w->Key(1, "block_resolution", std::to_string(c.tsdf.block_resolution));
  w->Comment(1, "Every Nth pixel of each row and column is fused (default " +
                    std::to_string(d.tsdf.depth_sampling_stride) + ").");
  w->Key(1, "depth_sampling_stride", std::to_string(c.tsdf.depth_sampling_stride));
  w->Comment(1,
             "Frames with more pixels are fused decimated, every f-th pixel and row "
             "(default " +
                 std::to_string(d.tsdf.max_fusion_pixels) + " = 1280 x 1024).");
  w->Key(1, "max_fusion_pixels", std::to_string(c.tsdf.max_fusion_pixels));
}

// The repair: on/off, mode, evidence, safe bound, rim band, incremental.
void DumpRepair(Writer* w, const RigConfig& c, const RigConfig& d) {
  w->Key(0, "repair", "");
  w->Comment(1, "Repair the fused cloud (claw holes, unseen top) before it goes out.");
  w->Key(1, "enabled", Bool(c.repair.enabled));
  w->Comment(1, "best (graspfill's) or paper (the method as published).");
  w->Key(1, "mode", c.repair.mode);
  w->Comment(1, "Use what the camera saw (the visibility record) in the repair.");
  w->Key(1, "use_evidence", Bool(c.repair.use_evidence));
  w->Comment(1, "The planner's safe bound's voxel edge [m]; 0 = no bound (default " +
                    FormatNumber(d.repair.safe_bound_voxel_m) + ").");
  w->Key(1, "safe_bound_voxel_m", FormatNumber(c.repair.safe_bound_voxel_m));
  w->Comment(1, "Best mode: boundary points this close to the top form its rim [m] (default " +
                    FormatNumber(d.repair.top_rim_band_m) + ").");
  w->Key(1, "top_rim_band_m", FormatNumber(c.repair.top_rim_band_m));
  w->Comment(1, "Live: update the last full repair between full repairs, which run behind");
  w->Comment(1, "(false: a full repair per published cloud).");
  w->Key(1, "incremental", Bool(c.repair.incremental));
}

// The refine: the pose refinement and object tracking.
void DumpRefine(Writer* w, const RigConfig& c, const RigConfig& d) {
  w->Key(0, "refine", "");
  w->Comment(1, "Correct each frame's gripper pose by registering the claw model to the depth");
  w->Comment(1, "(false: fuse at the logged poses).");
  w->Key(1, "enabled", Bool(c.refine.enabled));
  w->Comment(1, "Corrections beyond the prediction smaller than both are not fused (the");
  w->Comment(1, "registration's jitter) [m], [deg] (defaults " + FormatNumber(d.refine.min_correction_m) +
                    ", " + FormatNumber(d.refine.min_correction_deg) + ").");
  w->Key(1, "min_correction_m", FormatNumber(c.refine.min_correction_m));
  w->Key(1, "min_correction_deg", FormatNumber(c.refine.min_correction_deg));
  w->Comment(1, "Follow the object slipping in the grasp (frame-to-model tracking).");
  w->Key(1, "track_object", Bool(c.refine.track_object));
  w->Comment(1, "Divide the depth by the scale error the claw's size in it shows, once confident");
  w->Comment(1, "(false: only reported, in the replay report's refine.depth_scale).");
  w->Key(1, "apply_depth_scale", Bool(c.refine.apply_depth_scale));
}

// The channels: the LCM channel names.
void DumpChannels(Writer* w, const RigConfig& c) {
  w->Comment(0, "LCM channels.");
  w->Key(0, "channels", "");
  w->Key(1, "depth", Quoted(c.channels.depth));
  w->Key(1, "gripper_state", Quoted(c.channels.gripper_state));
  w->Key(1, "object_cloud", Quoted(c.channels.object_cloud));
  w->Key(1, "status", Quoted(c.channels.status));
  w->Key(1, "session", Quoted(c.channels.session));
  w->Key(1, "collision_mesh", Quoted(c.channels.collision_mesh));
}

// The collision_mesh: the planner mesh's size or convex hull.
void DumpCollisionMesh(Writer* w, const RigConfig& c, const RigConfig& d) {
  w->Key(0, "collision_mesh", "");
  w->Comment(1, "replay --mesh-out: at most this many triangles, decimated, watertight, holding");
  w->Comment(1, "the cloud (default " + std::to_string(d.collision_mesh.max_triangles) + ").");
  w->Key(1, "max_triangles", std::to_string(c.collision_mesh.max_triangles));
  w->Comment(1, "The convex hull instead of the decimated shape.");
  w->Key(1, "convex_hull", Bool(c.collision_mesh.convex_hull));
}

// The rates: live publishing and status periods.
void DumpRates(Writer* w, const RigConfig& c, const RigConfig& d) {
  w->Key(0, "rates", "");
  w->Comment(1, "live: publish the cloud every N fused frames; 0 = only at each grasp's end");
  w->Comment(1, "(default " + std::to_string(d.rates.publish_every_n_frames) + ").");
  w->Key(1, "publish_every_n_frames", std::to_string(c.rates.publish_every_n_frames));
  w->Comment(1,
             "live: the module status's period [s] (default " + FormatNumber(d.rates.status_period_s) + ").");
  w->Key(1, "status_period_s", FormatNumber(c.rates.status_period_s));
}

// The compute: OpenMP threads.
void DumpCompute(Writer* w, const RigConfig& c, const RigConfig& d) {
  w->Key(0, "compute", "");
  w->Comment(1, "OpenMP threads of each pipeline and repair call (Open3D's TSDF integration):");
  w->Comment(1, "1 = the calling thread alone, N = at most N, 0 = OpenMP's own count, a thread");
  w->Comment(1, "per core (default " + std::to_string(d.compute.num_threads) + ").");
  w->Key(1, "num_threads", std::to_string(c.compute.num_threads));
}
}  // namespace

std::string DumpRigConfig(const RigConfig& c) {
  const RigConfig d;  // the defaults, for the comments
  Writer w;
  w.Comment(0, "graspfill rig config (`graspfill config --dump-defaults` writes the defaults).");
  w.Comment(0, "`graspfill replay --config FILE` and `graspfill live --config FILE` read it.");
  w.Comment(0, "Units are in the names: _m meters, _s seconds, _px pixels. Precedence, lowest");
  w.Comment(0, "first: the defaults, the recording's (or the bus's) session description, this");
  w.Comment(0, "file, explicit command-line flags. `null` leaves a value to the session");
  w.Comment(0, "description (else the default commented above it). Keys left out keep their");
  w.Comment(0, "defaults; an unknown key, a bad value or a number with trailing text is an error.");
  w.Blank();
  DumpCamera(&w, c, d);
  w.Blank();
  DumpRobot(&w, c, d);
  w.Blank();
  DumpClaw(&w, c);
  w.Blank();
  DumpWorkspace(&w, c);
  w.Blank();
  DumpTsdf(&w, c, d);
  w.Blank();
  DumpRepair(&w, c, d);
  w.Blank();
  DumpRefine(&w, c, d);
  w.Blank();
  DumpChannels(&w, c);
  w.Blank();
  DumpCollisionMesh(&w, c, d);
  w.Blank();
  DumpRates(&w, c, d);
  w.Blank();
  DumpCompute(&w, c, d);
  return w.str();
}

}  // namespace graspfill::rt
