// SPDX-License-Identifier: BSD-3-Clause
// The rig config's equality, Validate and its mapping onto the libraries'
// config structs; the dump and the parser are rig_config_dump.cpp and
// rig_config_parse.cpp.
#include "config/rig_config.hpp"

#include <cmath>

#include "config/rig_config_checks.hpp"
#include "graspfill/io/channel_names.hpp"
#include "graspfill/mesh/planner_mesh.hpp"
#include "graspfill/pipeline/pipeline.hpp"
#include "graspfill/repair/repairer.hpp"

namespace graspfill::rt {

using namespace internal;  // the ranges and checks (rig_config_checks.hpp)

// ---- equality ----

bool RigConfig::Intrinsics::operator==(const Intrinsics& o) const {
  return width_px == o.width_px && height_px == o.height_px && fx_px == o.fx_px && fy_px == o.fy_px &&
         cx_px == o.cx_px && cy_px == o.cy_px;
}
bool RigConfig::Camera::operator==(const Camera& o) const {
  return device == o.device && width_px == o.width_px && height_px == o.height_px && fps == o.fps &&
         depth_units == o.depth_units && intrinsics_override == o.intrinsics_override &&
         max_depth_pixels == o.max_depth_pixels && reject_depth_edges == o.reject_depth_edges &&
         depth_scale == o.depth_scale;
}
bool RigConfig::Pose::operator==(const Pose& o) const {
  return translation_m == o.translation_m && rotation_wxyz == o.rotation_wxyz;
}
bool RigConfig::Robot::operator==(const Robot& o) const {
  return T_C_B == o.T_C_B && clock_offset_s == o.clock_offset_s && max_pose_gap_s == o.max_pose_gap_s;
}
bool RigConfig::Claw::operator==(const Claw& o) const { return spec == o.spec && mesh_root == o.mesh_root; }
bool RigConfig::Box::operator==(const Box& o) const { return min_G_m == o.min_G_m && max_G_m == o.max_G_m; }
bool RigConfig::Tsdf::operator==(const Tsdf& o) const {
  return voxel_m == o.voxel_m && sdf_trunc_voxels == o.sdf_trunc_voxels &&
         block_resolution == o.block_resolution && depth_sampling_stride == o.depth_sampling_stride &&
         max_fusion_pixels == o.max_fusion_pixels;
}
bool RigConfig::Repair::operator==(const Repair& o) const {
  return enabled == o.enabled && mode == o.mode && use_evidence == o.use_evidence &&
         safe_bound_voxel_m == o.safe_bound_voxel_m && top_rim_band_m == o.top_rim_band_m &&
         incremental == o.incremental;
}
bool RigConfig::Refine::operator==(const Refine& o) const {
  return enabled == o.enabled && min_correction_m == o.min_correction_m &&
         min_correction_deg == o.min_correction_deg && track_object == o.track_object &&
         apply_depth_scale == o.apply_depth_scale;
}
bool RigConfig::Channels::operator==(const Channels& o) const {
  return depth == o.depth && gripper_state == o.gripper_state && object_cloud == o.object_cloud &&
         status == o.status && session == o.session && collision_mesh == o.collision_mesh;
}
bool RigConfig::CollisionMesh::operator==(const CollisionMesh& o) const {
  return max_triangles == o.max_triangles && convex_hull == o.convex_hull;
}
bool RigConfig::Rates::operator==(const Rates& o) const {
  return publish_every_n_frames == o.publish_every_n_frames && status_period_s == o.status_period_s;
}
bool RigConfig::Compute::operator==(const Compute& o) const { return num_threads == o.num_threads; }
bool RigConfig::operator==(const RigConfig& o) const {
  return camera == o.camera && robot == o.robot && claw == o.claw && workspace == o.workspace &&
         tsdf == o.tsdf && repair == o.repair && refine == o.refine && channels == o.channels &&
         collision_mesh == o.collision_mesh && rates == o.rates && compute == o.compute;
}

Eigen::Isometry3d RigConfig::Pose::ToIsometry() const {
  const Eigen::Quaterniond q(rotation_wxyz[0], rotation_wxyz[1], rotation_wxyz[2], rotation_wxyz[3]);
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
  CheckRange("camera.depth_scale", camera.depth_scale, kDepthScale);
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

// ---- onto the existing structs ----

void ApplyToPipeline(const RigConfig& c, PipelineConfig* p) {
  if (c.tsdf.voxel_m) p->tsdf.voxel_m = *c.tsdf.voxel_m;
  p->tsdf.sdf_trunc_m = c.tsdf.sdf_trunc_voxels * p->tsdf.voxel_m;
  p->tsdf.block_resolution = c.tsdf.block_resolution;
  p->tsdf.depth_sampling_stride = c.tsdf.depth_sampling_stride;
  p->max_fusion_pixels = c.tsdf.max_fusion_pixels;
  p->reject_depth_edges = c.camera.reject_depth_edges;
  p->refine.known_depth_scale = c.camera.depth_scale;
  if (c.workspace) {
    p->workspace.min_G =
        Eigen::Vector3d(c.workspace->min_G_m[0], c.workspace->min_G_m[1], c.workspace->min_G_m[2]);
    p->workspace.max_G =
        Eigen::Vector3d(c.workspace->max_G_m[0], c.workspace->max_G_m[1], c.workspace->max_G_m[2]);
  }
  p->max_pose_gap_us = std::llround(c.robot.max_pose_gap_s * 1e6);
  p->refine.enabled = c.refine.enabled;
  p->refine.min_correction_m = c.refine.min_correction_m;
  p->refine.min_correction_deg = c.refine.min_correction_deg;
  p->refine.apply_depth_scale = c.refine.apply_depth_scale;
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
