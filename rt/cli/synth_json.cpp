// SPDX-License-Identifier: BSD-3-Clause
#include "synth_json.hpp"

#include <string>

#include "graspfill/io/messages.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"

namespace graspfill::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

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

json RigErrorsJson(const synth::RigErrors& rig) {
  const synth::RigErrorConfig& c = rig.config();
  const Eigen::AngleAxisd error(rig.hand_eye_error().linear());
  return {{"doc",
           "a state stamped t logs E_C * T_C_G_true(t + clock_offset) * N_k; frames and "
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
  return {{"doc",
           "the object slides by displacement_G_m = distance_m * direction_G (in G) "
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
          {"mixed_pixel_prob", s.mixed_pixel_prob},
          {"projector_shadow", s.projector_shadow},
          {"dark_patch_share", s.dark_patch_share},
          {"dark_patch_size_m", s.dark_patch_size_m},
          {"depth_scale", s.depth_scale},
          {"intrinsics_scale", s.intrinsics_scale},
          {"wobble_m", s.wobble_m},
          {"wobble_period_s", s.wobble_period_s},
          {"model_doc",
           "Nguyen et al. 2012 axial noise, 1/8 px disparity "
           "quantization, grazing/edge/random dropouts, mixed pixels at edges; "
           "projector_shadow: no depth where the projector (baseline_m along +x of C) "
           "cannot light the surface; dark patches: that share of the object's surface "
           "returns nothing, in blobs of about dark_patch_size_m; "
           "depth_scale: measured = scale x true; intrinsics_scale: the frames' "
           "stated fx, fy over the true ones; wobble: wobble_m sin(2 pi t / period)"}};
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

}  // namespace

void WriteClawDescription(const claw::ClawModel& model, const fs::path& dir, io::IfExists if_exists) {
  fs::create_directories(dir);
  json links = json::array();
  for (const claw::Link& link : model.links()) {
    const std::string mesh_file = link.name + ".ply";
    io::WriteMeshPly((dir / mesh_file).string(), link.mesh, if_exists);
    json j = {{"name", link.name}, {"mesh", mesh_file}, {"mesh_origin", Pose(link.T_link_mesh)}};
    if (link.parent >= 0) j["parent"] = model.links()[link.parent].name;
    if (link.joint.type != claw::JointType::kFixed) {
      j["joint"] = {{"type", link.joint.type == claw::JointType::kPrismatic ? "prismatic" : "revolute"},
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
  const json description = {{"name", model.name()},
                            {"opening_doc", "radius of the fingers' inner faces from G's z axis [m]"},
                            {"links", links}};
  io::WriteFileAtomically((dir / "claw.json").string(), description.dump(2) + "\n", "cannot write",
                          if_exists);
}

json SceneJson(const synth::Scene& scene, const SynthOptions& o, const io::ChannelNames& ch,
               int64_t log_bytes, size_t gripper_states, const synth::RigErrors& rig) {
  const synth::SceneConfig& c = scene.config();
  const synth::Placement& p = scene.placement();
  const Eigen::AlignedBox3d workspace = scene.WorkspaceBoxG(0.02);
  json j = {
      {"format", "graspfill-synth-scene/1"},
      {"software_version", io::SoftwareVersion()},
      {"frames_doc",
       "geometry in the gripper frame G (origin palm face centre, +z approach); "
       "T_A_B maps points from B to A; meters, microseconds"},
      {"object", ObjectJson(scene, o)},
      {"claw",
       {{"type", c.claw_model ? c.claw_model->name() : synth::ClawTypeName(c.claw)},
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
      {"intrinsics",
       {{"width", c.intrinsics.width},
        {"height", c.intrinsics.height},
        {"fx", c.intrinsics.fx},
        {"fy", c.intrinsics.fy},
        {"cx", c.intrinsics.cx},
        {"cy", c.intrinsics.cy}}},
      {"sensor", SensorJson(c.sensor, o.ideal)},
      {"placement", PlacementJson(c.placement, p)},
      {"motion", MotionJson(scene)},
      {"environment",
       {{"wall_distance_m", c.environment.wall_distance_m},
        {"arm_radius_m", c.environment.arm_radius_m},
        {"arm_length_m", c.environment.arm_length_m}}},
      {"workspace_box_G",
       {{"min", Vec(workspace.min())},
        {"max", Vec(workspace.max())},
        {"doc",
         "object bounding box in G grown by 2 cm, cut at the "
         "palm face z = 0"}}},
      {"log", LogJson(scene, ch, log_bytes, gripper_states)},
      {"rig_errors", RigErrorsJson(rig)},
      {"ground_truth",
       {{"mesh", "gt_mesh.ply"},
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

}  // namespace graspfill::cli
