// SPDX-License-Identifier: BSD-3-Clause
#include "config/rig_config.hpp"

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <functional>
#include <set>
#include <sstream>
#include <system_error>
#include <vector>

#include "config/number_text.hpp"
#include "graspfill/core/openmp_threads.hpp"
#include "graspfill/core/regular_file.hpp"
#include "graspfill/fusion/tsdf_fusion.hpp"
#include "graspfill/io/channel_names.hpp"
#include "graspfill/mesh/planner_mesh.hpp"
#include "graspfill/pipeline/pipeline.hpp"
#include "graspfill/repair/repairer.hpp"

namespace graspfill::rt {

// ---- ranges: one table for the parser and Validate ----

namespace {

struct Range {
  double min;
  double max;
  const char* unit;
};

constexpr Range kVideoPx{0, 16384, "pixels"};
constexpr Range kFps{0, 1000, "frames/s"};
constexpr Range kImagePx{1, 16384, "pixels"};
constexpr Range kDepthPixels{1, static_cast<double>(io::kMaxDepthPixels), "pixels"};
constexpr Range kFocalPx{1.0, 100000.0, "pixels"};
constexpr Range kCentrePx{-100000.0, 100000.0, "pixels"};
constexpr Range kTranslationM{-io::kMaxHandEyeTranslationM, io::kMaxHandEyeTranslationM, "m"};
constexpr Range kQuaternion{-1.0, 1.0, ""};
constexpr Range kClockOffsetS{-3600.0, 3600.0, "s"};
constexpr Range kPoseGapS{0.001, 1.0, "s"};
constexpr Range kBoxM{-io::kMaxWorkspaceM, io::kMaxWorkspaceM, "m"};  // session_limits.hpp
constexpr Range kVoxelM{io::kMinVoxelM, io::kMaxVoxelM, "m"};
constexpr Range kTruncVoxels{1.5, 32.0, "voxels"};
constexpr Range kBlockResolution{2, 128, "voxels"};
constexpr Range kStride{1, 16, "pixels"};
constexpr Range kFusionPixels{64 * 48, 4096 * 4096, "pixels"};
constexpr Range kSafeBoundM{0.0, 0.1, "m"};  // and 0 or >= kMinSafeBoundM
constexpr double kMinSafeBoundM = 0.0005;
constexpr Range kRimBandM{0.0, 0.5, "m"};
constexpr Range kCorrectionM{0.0, 0.005, "m"};
constexpr Range kCorrectionDeg{0.0, 2.0, "deg"};
constexpr Range kPublishEvery{0, 100000, "frames"};
constexpr Range kStatusPeriodS{0.05, 60.0, "s"};
constexpr Range kNumThreads{0, kMaxOpenMpThreads, "threads"};
constexpr Range kMeshTriangles{mesh::kMinPlannerTriangles, mesh::kMaxPlannerTriangles, "triangles"};
constexpr double kUnitTolerance = 1e-3;  // |norm - 1| of a typed quaternion
// yaml-cpp's parser refuses deeper nesting (its DepthGuard's default);
// named in the message instead of the library's "bad file".
constexpr int kMaxYamlDepth = 2000;

std::string FormatNumber(double v) {
  char buffer[64];
  // Shortest round-trip, fixed notation from 1e-4 up (as %g): 0.0005, not 5e-04.
  const auto [ptr, ec] = std::to_chars(buffer, buffer + sizeof(buffer), v, std::chars_format::general);
  if (ec != std::errc()) return std::to_string(v);
  return std::string(buffer, ptr);
}

std::string Expected(const Range& r) {
  return "expected " + FormatNumber(r.min) + ".." + FormatNumber(r.max) +
         (r.unit[0] != '\0' ? std::string(" ") + r.unit : std::string());
}

void CheckRange(const std::string& field, double v, const Range& r) {
  if (!std::isfinite(v) || v < r.min || v > r.max) {
    throw ConfigError(field, field + " '" + FormatNumber(v) + "': out of range, " + Expected(r));
  }
}

// One channel name, as LCM takes it (io/channel_names.hpp).
void CheckChannel(const std::string& field, const std::string& v) {
  if (v.empty()) throw ConfigError(field, field + ": must not be empty");
  if (const std::string defect = io::ChannelNameDefect(v); !defect.empty()) {
    throw ConfigError(field, field + " '" + v + "': " + defect);
  }
}

ConfigError SameChannelError(const std::string& role, const std::string& name,
                             const std::string& other_role) {
  const std::string field = "channels." + role;
  return ConfigError(field, field + " '" + name + "': the same name as channels." + other_role +
                                " (each channel needs its own)");
}

// Every name as LCM takes it, and no two the same.
void CheckChannels(const RigConfig::Channels& channels) {
  const std::optional<io::ChannelNameProblem> problem =
      io::FindChannelNameProblem(ToChannelNames(channels));
  if (!problem) return;
  CheckChannel("channels." + problem->role, problem->name);
  throw SameChannelError(problem->role, problem->name, problem->same_as);
}

void CheckOneOf(const std::string& field, const std::string& v,
                const std::vector<std::string>& allowed) {
  for (const std::string& a : allowed) {
    if (v == a) return;
  }
  std::string list;
  for (const std::string& a : allowed) list += (list.empty() ? "" : " or ") + a;
  throw ConfigError(field, field + " '" + v + "': expected " + list);
}

void CheckBox(const std::string& field, const RigConfig::Box& b) {
  static const char* kAxes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    CheckRange(field + ".min_G_m[" + std::to_string(k) + "]", b.min_G_m[k], kBoxM);
    CheckRange(field + ".max_G_m[" + std::to_string(k) + "]", b.max_G_m[k], kBoxM);
  }
  for (int k = 0; k < 3; ++k) {
    if (!(b.min_G_m[k] < b.max_G_m[k])) {
      const std::string f = field + ".max_G_m[" + std::to_string(k) + "]";
      throw ConfigError(f, f + ": must be greater than " + field + ".min_G_m[" +
                               std::to_string(k) + "] (" + kAxes[k] + ": " +
                               FormatNumber(b.min_G_m[k]) + " .. " + FormatNumber(b.max_G_m[k]) +
                               " m is empty)");
    }
  }
}

void CheckPose(const std::string& field, const RigConfig::Pose& p) {
  for (int k = 0; k < 3; ++k) {
    CheckRange(field + ".translation_m[" + std::to_string(k) + "]", p.translation_m[k],
               kTranslationM);
  }
  double norm2 = 0.0;
  for (int k = 0; k < 4; ++k) {
    CheckRange(field + ".rotation_wxyz[" + std::to_string(k) + "]", p.rotation_wxyz[k],
               kQuaternion);
    norm2 += p.rotation_wxyz[k] * p.rotation_wxyz[k];
  }
  const double norm = std::sqrt(norm2);
  if (!(std::abs(norm - 1.0) <= kUnitTolerance)) {
    const std::string f = field + ".rotation_wxyz";
    throw ConfigError(f, f + ": not a unit quaternion (norm " + FormatNumber(norm) +
                             "; expected 1 within " + FormatNumber(kUnitTolerance) + ")");
  }
}

void CheckIntrinsics(const std::string& field, const RigConfig::Intrinsics& K) {
  CheckRange(field + ".width_px", K.width_px, kImagePx);
  CheckRange(field + ".height_px", K.height_px, kImagePx);
  CheckRange(field + ".fx_px", K.fx_px, kFocalPx);
  CheckRange(field + ".fy_px", K.fy_px, kFocalPx);
  CheckRange(field + ".cx_px", K.cx_px, kCentrePx);
  CheckRange(field + ".cy_px", K.cy_px, kCentrePx);
}

void CheckSafeBound(const std::string& field, double v) {
  CheckRange(field, v, kSafeBoundM);
  if (v != 0.0 && v < kMinSafeBoundM) {
    throw ConfigError(field, field + " '" + FormatNumber(v) + "': expected 0 (no bound) or " +
                                 FormatNumber(kMinSafeBoundM) + "..0.1 m");
  }
}

}  // namespace

// ---- equality ----

bool RigConfig::Intrinsics::operator==(const Intrinsics& o) const {
  return width_px == o.width_px && height_px == o.height_px && fx_px == o.fx_px &&
         fy_px == o.fy_px && cx_px == o.cx_px && cy_px == o.cy_px;
}
bool RigConfig::Camera::operator==(const Camera& o) const {
  return device == o.device && width_px == o.width_px && height_px == o.height_px &&
         fps == o.fps && depth_units == o.depth_units &&
         intrinsics_override == o.intrinsics_override && max_depth_pixels == o.max_depth_pixels;
}
bool RigConfig::Pose::operator==(const Pose& o) const {
  return translation_m == o.translation_m && rotation_wxyz == o.rotation_wxyz;
}
bool RigConfig::Robot::operator==(const Robot& o) const {
  return T_C_B == o.T_C_B && clock_offset_s == o.clock_offset_s &&
         max_pose_gap_s == o.max_pose_gap_s;
}
bool RigConfig::Claw::operator==(const Claw& o) const {
  return spec == o.spec && mesh_root == o.mesh_root;
}
bool RigConfig::Box::operator==(const Box& o) const {
  return min_G_m == o.min_G_m && max_G_m == o.max_G_m;
}
bool RigConfig::Tsdf::operator==(const Tsdf& o) const {
  return voxel_m == o.voxel_m && sdf_trunc_voxels == o.sdf_trunc_voxels &&
         block_resolution == o.block_resolution &&
         depth_sampling_stride == o.depth_sampling_stride &&
         max_fusion_pixels == o.max_fusion_pixels;
}
bool RigConfig::Repair::operator==(const Repair& o) const {
  return enabled == o.enabled && mode == o.mode && use_evidence == o.use_evidence &&
         safe_bound_voxel_m == o.safe_bound_voxel_m && top_rim_band_m == o.top_rim_band_m &&
         incremental == o.incremental;
}
bool RigConfig::Refine::operator==(const Refine& o) const {
  return enabled == o.enabled && min_correction_m == o.min_correction_m &&
         min_correction_deg == o.min_correction_deg && track_object == o.track_object;
}
bool RigConfig::Channels::operator==(const Channels& o) const {
  return depth == o.depth && gripper_state == o.gripper_state &&
         object_cloud == o.object_cloud && status == o.status && session == o.session &&
         collision_mesh == o.collision_mesh;
}
bool RigConfig::CollisionMesh::operator==(const CollisionMesh& o) const {
  return max_triangles == o.max_triangles && convex_hull == o.convex_hull;
}
bool RigConfig::Rates::operator==(const Rates& o) const {
  return publish_every_n_frames == o.publish_every_n_frames &&
         status_period_s == o.status_period_s;
}
bool RigConfig::Compute::operator==(const Compute& o) const {
  return num_threads == o.num_threads;
}
bool RigConfig::operator==(const RigConfig& o) const {
  return camera == o.camera && robot == o.robot && claw == o.claw && workspace == o.workspace &&
         tsdf == o.tsdf && repair == o.repair && refine == o.refine && channels == o.channels &&
         collision_mesh == o.collision_mesh && rates == o.rates && compute == o.compute;
}

Eigen::Isometry3d RigConfig::Pose::ToIsometry() const {
  const Eigen::Quaterniond q(rotation_wxyz[0], rotation_wxyz[1], rotation_wxyz[2],
                             rotation_wxyz[3]);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(translation_m[0], translation_m[1], translation_m[2]);
  return T;
}

// ---- Validate ----

void RigConfig::Validate() const {
  CheckRange("camera.width_px", camera.width_px, kVideoPx);
  CheckRange("camera.height_px", camera.height_px, kVideoPx);
  CheckRange("camera.fps", camera.fps, kFps);
  CheckOneOf("camera.depth_units", camera.depth_units, {"mm", "100um"});
  if (camera.intrinsics_override) {
    CheckIntrinsics("camera.intrinsics_override", *camera.intrinsics_override);
  }
  CheckRange("camera.max_depth_pixels", camera.max_depth_pixels, kDepthPixels);
  if (robot.T_C_B) CheckPose("robot.T_C_B", *robot.T_C_B);
  CheckRange("robot.clock_offset_s", robot.clock_offset_s, kClockOffsetS);
  CheckRange("robot.max_pose_gap_s", robot.max_pose_gap_s, kPoseGapS);
  if (workspace) CheckBox("workspace", *workspace);
  if (tsdf.voxel_m) CheckRange("tsdf.voxel_m", *tsdf.voxel_m, kVoxelM);
  CheckRange("tsdf.sdf_trunc_voxels", tsdf.sdf_trunc_voxels, kTruncVoxels);
  CheckRange("tsdf.block_resolution", tsdf.block_resolution, kBlockResolution);
  CheckRange("tsdf.depth_sampling_stride", tsdf.depth_sampling_stride, kStride);
  CheckRange("tsdf.max_fusion_pixels", tsdf.max_fusion_pixels, kFusionPixels);
  CheckOneOf("repair.mode", repair.mode, {"best", "paper"});
  CheckSafeBound("repair.safe_bound_voxel_m", repair.safe_bound_voxel_m);
  CheckRange("repair.top_rim_band_m", repair.top_rim_band_m, kRimBandM);
  CheckRange("refine.min_correction_m", refine.min_correction_m, kCorrectionM);
  CheckRange("refine.min_correction_deg", refine.min_correction_deg, kCorrectionDeg);
  CheckChannels(channels);
  CheckRange("collision_mesh.max_triangles", collision_mesh.max_triangles, kMeshTriangles);
  CheckRange("rates.publish_every_n_frames", rates.publish_every_n_frames, kPublishEvery);
  CheckRange("rates.status_period_s", rates.status_period_s, kStatusPeriodS);
  CheckRange("compute.num_threads", compute.num_threads, kNumThreads);
}

// ---- Dump ----

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
    out_ << std::string(2 * indent, ' ') << key << ":" << (value.empty() ? "" : " " + value)
         << "\n";
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
  w->Comment(1, "depth sensors are ~5 MP; a 4096 x 4096 stream needs " +
                   std::to_string(io::kMaxDepthPixels) + ").");
  w->Key(1, "max_depth_pixels", std::to_string(c.camera.max_depth_pixels));
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
                   "; null: the session description's, else " +
                   FormatNumber(fusion::TsdfConfig{}.voxel_m) + ".");
  w->Key(1, "voxel_m", c.tsdf.voxel_m ? FormatNumber(*c.tsdf.voxel_m) : "null");
  w->Comment(1, "Truncation distance in voxels (default " + FormatNumber(d.tsdf.sdf_trunc_voxels) +
                   ").");
  w->Key(1, "sdf_trunc_voxels", FormatNumber(c.tsdf.sdf_trunc_voxels));
  w->Comment(1, "Open3D's voxel block edge [voxels] (default " +
                   std::to_string(d.tsdf.block_resolution) + ").");
  w->Key(1, "block_resolution", std::to_string(c.tsdf.block_resolution));
  w->Comment(1, "Every Nth pixel of each row and column is fused (default " +
                   std::to_string(d.tsdf.depth_sampling_stride) + ").");
  w->Key(1, "depth_sampling_stride", std::to_string(c.tsdf.depth_sampling_stride));
  w->Comment(1, "Frames with more pixels are fused decimated, every f-th pixel and row "
               "(default " + std::to_string(d.tsdf.max_fusion_pixels) + " = 1280 x 1024).");
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
  w->Comment(1, "live: the module status's period [s] (default " +
                   FormatNumber(d.rates.status_period_s) + ").");
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

// ---- Parse ----

namespace {

// Reads nodes into fields; every failure names the file, line and field.
class Reader {
 public:
  explicit Reader(std::string name) : name_(std::move(name)) {}

  [[noreturn]] void Fail(const YAML::Node& at, const std::string& field,
                         const std::string& message) const {
    throw ConfigError(field, Where(at) + message);
  }

  std::string Where(const YAML::Node& at) const {
    const YAML::Mark mark = at.Mark();
    if (mark.is_null()) return name_ + ": ";
    return name_ + ":" + std::to_string(mark.line + 1) + ": ";
  }

  static std::string Kind(const YAML::Node& n) {
    if (n.IsNull()) return "null";
    if (n.IsMap()) return "a map";
    if (n.IsSequence()) return "a list";
    if (n.IsScalar()) return n.Tag() == "?" ? "'" + n.Scalar() + "'" : "the string \"" + n.Scalar() + "\"";
    return "nothing";
  }

  // Calls `on_key(key, value, field)` for each entry of the map `node`;
  // an unknown or duplicate key, or a node that is not a map, fails.
  // `required`: every key in `keys` must be there.
  void Map(const YAML::Node& node, const std::string& path, const std::vector<std::string>& keys,
           const std::function<void(const std::string&, const YAML::Node&, const std::string&)>&
               on_key,
           bool required = false) const {
    const std::string where = path.empty() ? "the file" : path;
    if (!node.IsMap()) Fail(node, path, where + ": expected a map of keys, got " + Kind(node));
    std::set<std::string> seen;
    for (const auto& entry : node) {
      const YAML::Node& key_node = entry.first;
      if (!key_node.IsScalar()) Fail(key_node, path, where + ": a key that is not a name");
      const std::string key = key_node.Scalar();
      const std::string field = path.empty() ? key : path + "." + key;
      bool known = false;
      for (const std::string& k : keys) known = known || k == key;
      if (!known) {
        std::string list;
        for (const std::string& k : keys) list += (list.empty() ? "" : ", ") + k;
        Fail(key_node, field, "unknown key '" + field + "' (" + where + " has: " + list + ")");
      }
      if (!seen.insert(key).second) Fail(key_node, field, "duplicate key '" + field + "'");
      on_key(key, entry.second, field);
    }
    if (required) {
      for (const std::string& k : keys) {
        if (seen.count(k) == 0) {
          const std::string field = path + "." + k;
          Fail(node, field, field + ": missing (" + path + " needs all its keys)");
        }
      }
    }
  }

  double Number(const YAML::Node& n, const std::string& field, const Range& r) const {
    const std::string text = PlainScalar(n, field, "a number");
    try {
      return ReadNumber(field, text, r.min, r.max, r.unit);
    } catch (const std::invalid_argument& e) {
      Fail(n, field, e.what());
    }
  }

  int Integer(const YAML::Node& n, const std::string& field, const Range& r) const {
    const std::string text = PlainScalar(n, field, "an integer");
    try {
      return ReadInteger<int>(field, text, static_cast<int>(r.min), static_cast<int>(r.max));
    } catch (const std::invalid_argument& e) {
      Fail(n, field, e.what());
    }
  }

  bool Bool(const YAML::Node& n, const std::string& field) const {
    const std::string text = PlainScalar(n, field, "true or false");
    if (text == "true") return true;
    if (text == "false") return false;
    Fail(n, field, field + " '" + text + "': expected true or false");
  }

  std::string String(const YAML::Node& n, const std::string& field) const {
    if (!n.IsScalar()) Fail(n, field, field + ": expected a string, got " + Kind(n));
    return n.Scalar();
  }

  std::string OneOf(const YAML::Node& n, const std::string& field,
                    const std::vector<std::string>& allowed) const {
    const std::string v = String(n, field);
    try {
      CheckOneOf(field, v, allowed);
    } catch (const ConfigError& e) {
      Fail(n, field, e.what());
    }
    return v;
  }

  template <size_t N>
  std::array<double, N> Numbers(const YAML::Node& n, const std::string& field,
                                const Range& r) const {
    if (!n.IsSequence() || n.size() != N) {
      Fail(n, field, field + ": expected a list of " + std::to_string(N) + " numbers, got " +
                         (n.IsSequence() ? "a list of " + std::to_string(n.size()) : Kind(n)));
    }
    std::array<double, N> out{};
    for (size_t k = 0; k < N; ++k) out[k] = Number(n[k], field + "[" + std::to_string(k) + "]", r);
    return out;
  }

  // Runs a whole-value check, failing at `n`'s line.
  void Check(const YAML::Node& n, const std::function<void()>& check) const {
    try {
      check();
    } catch (const ConfigError& e) {
      Fail(n, e.field(), e.what());
    }
  }

 private:
  std::string PlainScalar(const YAML::Node& n, const std::string& field,
                          const std::string& what) const {
    if (!n.IsScalar() || n.Tag() != "?") {
      Fail(n, field, field + ": expected " + what + ", got " + Kind(n));
    }
    return n.Scalar();
  }

  std::string name_;
};

// The text's one YAML document (null: an empty file).
YAML::Node LoadOneDocument(const std::string& text, const std::string& name) {
  YAML::Node root;
  try {
    const std::vector<YAML::Node> documents = YAML::LoadAll(text);
    if (documents.size() > 1) {
      // yaml-cpp's Load would take the first and drop the rest unread.
      const YAML::Mark mark = documents[1].Mark();
      throw ConfigError("", name + (mark.is_null() ? "" : ":" + std::to_string(mark.line + 1)) +
                                ": a second YAML document (after '---'): a rig config is one "
                                "document; put everything in the first");
    }
    if (!documents.empty()) root = documents[0];
  } catch (const YAML::DeepRecursion& e) {
    // yaml-cpp words its depth limit "bad file".
    throw ConfigError("", name + ":" + std::to_string(e.mark.line + 1) +
                              ": not a rig config: nested more than " +
                              std::to_string(kMaxYamlDepth) +
                              " levels deep (a rig config nests 4: camera.intrinsics_override.fx_px, "
                              "robot.T_C_B.translation_m[0])");
  } catch (const YAML::Exception& e) {
    throw ConfigError("", name + ":" + std::to_string(e.mark.line + 1) + ": not YAML: " + e.msg);
  }
  return root;
}

RigConfig::Intrinsics ReadIntrinsics(const Reader& r, const YAML::Node& x, const std::string& f) {
  RigConfig::Intrinsics K;
  r.Map(x, f, {"width_px", "height_px", "fx_px", "fy_px", "cx_px", "cy_px"},
        [&](const std::string& kk, const YAML::Node& y, const std::string& ff) {
    if (kk == "width_px") K.width_px = r.Integer(y, ff, kImagePx);
    else if (kk == "height_px") K.height_px = r.Integer(y, ff, kImagePx);
    else if (kk == "fx_px") K.fx_px = r.Number(y, ff, kFocalPx);
    else if (kk == "fy_px") K.fy_px = r.Number(y, ff, kFocalPx);
    else if (kk == "cx_px") K.cx_px = r.Number(y, ff, kCentrePx);
    else K.cy_px = r.Number(y, ff, kCentrePx);
  }, /*required=*/true);
  return K;
}

void ReadCamera(const Reader& r, const YAML::Node& v, const std::string& path,
                RigConfig::Camera* cam) {
  r.Map(v, path, {"device", "width_px", "height_px", "fps", "depth_units", "intrinsics_override",
                  "max_depth_pixels"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
    if (k == "device") cam->device = r.String(x, f);
    else if (k == "max_depth_pixels") cam->max_depth_pixels = r.Integer(x, f, kDepthPixels);
    else if (k == "width_px") cam->width_px = r.Integer(x, f, kVideoPx);
    else if (k == "height_px") cam->height_px = r.Integer(x, f, kVideoPx);
    else if (k == "fps") cam->fps = r.Integer(x, f, kFps);
    else if (k == "depth_units") cam->depth_units = r.OneOf(x, f, {"mm", "100um"});
    else if (x.IsNull()) cam->intrinsics_override.reset();
    else cam->intrinsics_override = ReadIntrinsics(r, x, f);
  });
}

void ReadRobot(const Reader& r, const YAML::Node& v, const std::string& path,
               RigConfig::Robot* robot) {
  r.Map(v, path, {"T_C_B", "clock_offset_s", "max_pose_gap_s"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
    if (k == "clock_offset_s") robot->clock_offset_s = r.Number(x, f, kClockOffsetS);
    else if (k == "max_pose_gap_s") robot->max_pose_gap_s = r.Number(x, f, kPoseGapS);
    else if (x.IsNull()) robot->T_C_B.reset();
    else {
      RigConfig::Pose pose;
      r.Map(x, f, {"translation_m", "rotation_wxyz"},
            [&](const std::string& kk, const YAML::Node& y, const std::string& ff) {
        if (kk == "translation_m") pose.translation_m = r.Numbers<3>(y, ff, kTranslationM);
        else pose.rotation_wxyz = r.Numbers<4>(y, ff, kQuaternion);
      }, /*required=*/true);
      r.Check(x["rotation_wxyz"], [&] { CheckPose(f, pose); });
      robot->T_C_B = pose;
    }
  });
}

// null: none (the session description's).
std::optional<RigConfig::Box> ReadWorkspace(const Reader& r, const YAML::Node& v,
                                            const std::string& path) {
  if (v.IsNull()) return std::nullopt;
  RigConfig::Box box;
  r.Map(v, path, {"min_G_m", "max_G_m"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
    (k == "min_G_m" ? box.min_G_m : box.max_G_m) = r.Numbers<3>(x, f, kBoxM);
  }, /*required=*/true);
  r.Check(v["max_G_m"], [&] { CheckBox(path, box); });
  return box;
}

void ReadTsdf(const Reader& r, const YAML::Node& v, const std::string& path, RigConfig::Tsdf* tsdf) {
  r.Map(v, path, {"voxel_m", "sdf_trunc_voxels", "block_resolution", "depth_sampling_stride",
                  "max_fusion_pixels"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
    if (k == "voxel_m") {
      if (x.IsNull()) tsdf->voxel_m.reset();
      else tsdf->voxel_m = r.Number(x, f, kVoxelM);
    }
    else if (k == "sdf_trunc_voxels") tsdf->sdf_trunc_voxels = r.Number(x, f, kTruncVoxels);
    else if (k == "block_resolution") tsdf->block_resolution = r.Integer(x, f, kBlockResolution);
    else if (k == "depth_sampling_stride") tsdf->depth_sampling_stride = r.Integer(x, f, kStride);
    else tsdf->max_fusion_pixels = r.Integer(x, f, kFusionPixels);
  });
}

void ReadRepair(const Reader& r, const YAML::Node& v, const std::string& path,
                RigConfig::Repair* repair) {
  r.Map(v, path, {"enabled", "mode", "use_evidence", "safe_bound_voxel_m", "top_rim_band_m",
                  "close_unknown_top", "incremental"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
    if (k == "enabled") repair->enabled = r.Bool(x, f);
    else if (k == "mode") repair->mode = r.OneOf(x, f, {"best", "paper"});
    else if (k == "use_evidence") repair->use_evidence = r.Bool(x, f);
    else if (k == "safe_bound_voxel_m") {
      repair->safe_bound_voxel_m = r.Number(x, f, kSafeBoundM);
      r.Check(x, [&] { CheckSafeBound(f, repair->safe_bound_voxel_m); });
    }
    else if (k == "top_rim_band_m") repair->top_rim_band_m = r.Number(x, f, kRimBandM);
    else if (k == "incremental") repair->incremental = r.Bool(x, f);
    else r.Bool(x, f);  // close_unknown_top: read and ignored since the top search (2026-12)
  });
}

void ReadChannels(const Reader& r, const YAML::Node& v, const std::string& path,
                  RigConfig::Channels* channels) {
  r.Map(v, path, {"depth", "gripper_state", "object_cloud", "status", "session", "collision_mesh"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
    std::string value = r.String(x, f);
    r.Check(x, [&] { CheckChannel(f, value); });
    if (k == "depth") channels->depth = value;
    else if (k == "gripper_state") channels->gripper_state = value;
    else if (k == "object_cloud") channels->object_cloud = value;
    else if (k == "status") channels->status = value;
    else if (k == "session") channels->session = value;
    else channels->collision_mesh = value;
  });
  // Two the same: named at the line of the later one the file sets
  // (the other may be a default).
  if (const auto problem = io::FindChannelNameProblem(ToChannelNames(*channels))) {
    const bool later_set = v[problem->role].IsDefined();
    const std::string& role = later_set ? problem->role : problem->same_as;
    const std::string& other = later_set ? problem->same_as : problem->role;
    r.Check(v[role], [&] { throw SameChannelError(role, problem->name, other); });
  }
}

void ReadClaw(const Reader& r, const YAML::Node& v, const std::string& path, RigConfig::Claw* claw) {
  r.Map(v, path, {"spec", "mesh_root"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
    (k == "spec" ? claw->spec : claw->mesh_root) = r.String(x, f);
  });
}

void ReadRefine(const Reader& r, const YAML::Node& v, const std::string& path,
                RigConfig::Refine* refine) {
  r.Map(v, path, {"enabled", "min_correction_m", "min_correction_deg", "track_object"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
    if (k == "enabled") refine->enabled = r.Bool(x, f);
    else if (k == "min_correction_m") refine->min_correction_m = r.Number(x, f, kCorrectionM);
    else if (k == "min_correction_deg") refine->min_correction_deg = r.Number(x, f, kCorrectionDeg);
    else refine->track_object = r.Bool(x, f);
  });
}

void ReadCollisionMesh(const Reader& r, const YAML::Node& v, const std::string& path,
                       RigConfig::CollisionMesh* mesh) {
  r.Map(v, path, {"max_triangles", "convex_hull"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
    if (k == "max_triangles") mesh->max_triangles = r.Integer(x, f, kMeshTriangles);
    else mesh->convex_hull = r.Bool(x, f);
  });
}

void ReadCompute(const Reader& r, const YAML::Node& v, const std::string& path,
                 RigConfig::Compute* compute) {
  r.Map(v, path, {"num_threads"}, [&](const std::string&, const YAML::Node& x, const std::string& f) {
    compute->num_threads = r.Integer(x, f, kNumThreads);
  });
}

void ReadRates(const Reader& r, const YAML::Node& v, const std::string& path,
               RigConfig::Rates* rates) {
  r.Map(v, path, {"publish_every_n_frames", "status_period_s"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
    if (k == "publish_every_n_frames") {
      rates->publish_every_n_frames = r.Integer(x, f, kPublishEvery);
    } else {
      rates->status_period_s = r.Number(x, f, kStatusPeriodS);
    }
  });
}

}  // namespace

RigConfig ParseRigConfig(const std::string& text, const std::string& name) {
  const YAML::Node root = LoadOneDocument(text, name);
  RigConfig c;
  if (root.IsNull()) return c;  // an empty file: the defaults
  const Reader r(name);
  r.Map(root, "",
        {"camera", "robot", "claw", "workspace", "tsdf", "repair", "refine", "channels",
         "collision_mesh", "rates", "compute"},
        [&](const std::string& key, const YAML::Node& v, const std::string& path) {
    if (key == "camera") ReadCamera(r, v, path, &c.camera);
    else if (key == "robot") ReadRobot(r, v, path, &c.robot);
    else if (key == "workspace") c.workspace = ReadWorkspace(r, v, path);
    else if (key == "tsdf") ReadTsdf(r, v, path, &c.tsdf);
    else if (key == "repair") ReadRepair(r, v, path, &c.repair);
    else if (key == "channels") ReadChannels(r, v, path, &c.channels);
    else if (key == "claw") ReadClaw(r, v, path, &c.claw);
    else if (key == "refine") ReadRefine(r, v, path, &c.refine);
    else if (key == "collision_mesh") ReadCollisionMesh(r, v, path, &c.collision_mesh);
    else if (key == "compute") ReadCompute(r, v, path, &c.compute);
    else ReadRates(r, v, path, &c.rates);
  });
  try {
    c.Validate();  // every field was checked as read; this is the net under it
  } catch (const ConfigError& e) {
    throw ConfigError(e.field(), name + ": " + e.what());
  }
  return c;
}

RigConfig LoadRigConfig(const std::string& path) {
  // A config is a few kB; anything huge is a wrong path. A FIFO or a device
  // is refused unopened (it could block or never end).
  constexpr int64_t kMaxBytes = 1 << 20;
  std::string text;
  try {
    text = ReadRegularFile(path, kMaxBytes, "cannot read config");
  } catch (const std::runtime_error& e) {
    throw ConfigError("", e.what());
  }
  return ParseRigConfig(text, path);
}

// ---- onto the existing structs ----

void ApplyToPipeline(const RigConfig& c, PipelineConfig* p) {
  if (c.tsdf.voxel_m) p->tsdf.voxel_m = *c.tsdf.voxel_m;
  p->tsdf.sdf_trunc_m = c.tsdf.sdf_trunc_voxels * p->tsdf.voxel_m;
  p->tsdf.block_resolution = c.tsdf.block_resolution;
  p->tsdf.depth_sampling_stride = c.tsdf.depth_sampling_stride;
  p->max_fusion_pixels = c.tsdf.max_fusion_pixels;
  if (c.workspace) {
    p->workspace.min_G = Eigen::Vector3d(c.workspace->min_G_m[0], c.workspace->min_G_m[1],
                                         c.workspace->min_G_m[2]);
    p->workspace.max_G = Eigen::Vector3d(c.workspace->max_G_m[0], c.workspace->max_G_m[1],
                                         c.workspace->max_G_m[2]);
  }
  p->max_pose_gap_us = std::llround(c.robot.max_pose_gap_s * 1e6);
  p->refine.enabled = c.refine.enabled;
  p->refine.min_correction_m = c.refine.min_correction_m;
  p->refine.min_correction_deg = c.refine.min_correction_deg;
  p->track_object.enabled = c.refine.track_object;
  // The record keeps the safe bound at the repair's voxel (0: none).
  p->visibility.safe_bound_voxel_m = c.repair.safe_bound_voxel_m;
  p->num_threads = c.compute.num_threads;
}

void ApplyToRepair(const RigConfig& c, repair::RepairConfig* r) {
  r->mode = c.repair.mode == "paper" ? repair::RepairMode::kPaper : repair::RepairMode::kBest;
  r->safe_bound_voxel_m = c.repair.safe_bound_voxel_m;
  r->top_rim_band_m = c.repair.top_rim_band_m;
  r->num_threads = c.compute.num_threads;
}

void ApplyToCollisionMesh(const RigConfig& c, mesh::PlannerMeshConfig* m) {
  m->max_triangles = c.collision_mesh.max_triangles;
  m->convex_hull = c.collision_mesh.convex_hull;
}

io::ChannelNames ToChannelNames(const RigConfig::Channels& ch) {
  io::ChannelNames names;
  names.depth = ch.depth;
  names.gripper_state = ch.gripper_state;
  names.object_cloud = ch.object_cloud;
  names.status = ch.status;
  names.session = ch.session;
  names.collision_mesh = ch.collision_mesh;
  return names;
}

std::optional<CameraIntrinsics> IntrinsicsOverride(const RigConfig& c) {
  if (!c.camera.intrinsics_override) return std::nullopt;
  const RigConfig::Intrinsics& K = *c.camera.intrinsics_override;
  CameraIntrinsics out;
  out.width = K.width_px;
  out.height = K.height_px;
  out.fx = K.fx_px;
  out.fy = K.fy_px;
  out.cx = K.cx_px;
  out.cy = K.cy_px;
  return out;
}

int64_t ClockOffsetUs(const RigConfig& c) { return std::llround(c.robot.clock_offset_s * 1e6); }

SourceOverrides ToSourceOverrides(const RigConfig& c) {
  SourceOverrides o;
  if (c.robot.T_C_B) {
    o.T_C_B = c.robot.T_C_B->ToIsometry();
    o.T_C_B_from_session = false;
  }
  o.intrinsics = IntrinsicsOverride(c);
  o.intrinsics_from_session = !o.intrinsics.has_value();
  o.gripper_clock_offset_us = ClockOffsetUs(c);
  return o;
}

}  // namespace graspfill::rt
