// SPDX-License-Identifier: BSD-3-Clause
// The rig config file (rt/config/rig_config.hpp): its defaults are the
// libraries' defaults, dump -> parse gives the same struct back, and every
// bad value is refused naming the file, the line and the field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "config/rig_config.hpp"
#include "graspfill/fusion/tsdf_fusion.hpp"
#include "graspfill/mesh/planner_mesh.hpp"
#include "graspfill/pipeline/pipeline.hpp"
#include "graspfill/repair/repairer.hpp"
#include "module/grasp_module.hpp"
#include "module/session_loop.hpp"

namespace graspfill::rt {
namespace {

// Every field away from its default (optionals set), with values that need
// all 17 digits to round-trip.
RigConfig EveryFieldChanged() {
  RigConfig c;
  c.camera.device = "graspfill-replay:/tmp/a \"quoted\" log.lcmlog";
  c.camera.width_px = 848;
  c.camera.height_px = 480;
  c.camera.fps = 60;
  c.camera.depth_units = "100um";
  c.camera.intrinsics_override = RigConfig::Intrinsics{848, 480, 421.1 + 1e-13, 421.3, 424.7, 239.1};
  c.camera.max_depth_pixels = 4096 * 4096;
  c.camera.reject_depth_edges = true;
  c.camera.depth_scale = 1.0 + 1.0 / 3.0 * 0.03;
  const double s = std::sqrt(0.5);
  c.robot.T_C_B = RigConfig::Pose{{0.1 + 0.2, -0.25, 0.8}, {s, 0.0, s, 0.0}};
  c.robot.clock_offset_s = -0.0123;
  c.robot.max_pose_gap_s = 0.07;
  c.claw.spec = "config/claws/robotiq_3f.json";
  c.claw.mesh_root = "/opt/robot meshes";
  c.workspace = RigConfig::Box{{-0.05, -0.06, 0.01}, {0.05, 0.06, 0.2}};
  c.tsdf.voxel_m = 0.002;
  c.tsdf.sdf_trunc_voxels = 5.5;
  c.tsdf.block_resolution = 8;
  c.tsdf.depth_sampling_stride = 1;
  c.tsdf.max_fusion_pixels = 1920 * 1080;
  c.repair.enabled = false;
  c.repair.mode = "paper";
  c.repair.use_evidence = false;
  c.repair.safe_bound_voxel_m = 0.0;
  c.repair.top_rim_band_m = 0.006;
  c.repair.incremental = false;
  c.refine.enabled = false;
  c.refine.min_correction_m = 0.00025;
  c.refine.min_correction_deg = 0.3;
  c.refine.track_object = true;
  c.refine.apply_depth_scale = false;
  c.channels = {"D", "G", "C", "S", "SESSION_2", "MESH_2"};
  c.collision_mesh.max_triangles = 1200;
  c.collision_mesh.convex_hull = true;
  c.rates.publish_every_n_frames = 0;
  c.rates.status_period_s = 0.25;
  return c;
}

TEST(RigConfig, DefaultsAreTheLibrariesDefaults) {
  const RigConfig c;
  PipelineConfig pipeline;
  pipeline.tsdf.sdf_trunc_m = 1.0;  // must come back as the default's
  pipeline.max_pose_gap_us = 1;
  pipeline.reject_depth_edges = !PipelineConfig{}.reject_depth_edges;  // must come back
  ApplyToPipeline(c, &pipeline);
  const PipelineConfig want;
  EXPECT_EQ(pipeline.reject_depth_edges, want.reject_depth_edges);
  EXPECT_EQ(pipeline.tsdf.voxel_m, want.tsdf.voxel_m);
  EXPECT_EQ(pipeline.tsdf.sdf_trunc_m, want.tsdf.sdf_trunc_m);
  EXPECT_EQ(pipeline.tsdf.block_resolution, want.tsdf.block_resolution);
  EXPECT_EQ(pipeline.tsdf.depth_sampling_stride, want.tsdf.depth_sampling_stride);
  EXPECT_EQ(pipeline.max_fusion_pixels, want.max_fusion_pixels);
  EXPECT_EQ(pipeline.max_pose_gap_us, want.max_pose_gap_us);
  EXPECT_EQ(pipeline.refine.enabled, want.refine.enabled);
  EXPECT_EQ(pipeline.refine.min_correction_m, want.refine.min_correction_m);
  EXPECT_EQ(pipeline.refine.min_correction_deg, want.refine.min_correction_deg);
  EXPECT_EQ(pipeline.refine.apply_depth_scale, want.refine.apply_depth_scale);
  EXPECT_EQ(pipeline.refine.known_depth_scale, want.refine.known_depth_scale);
  EXPECT_EQ(pipeline.track_object.enabled, want.track_object.enabled);
  EXPECT_EQ(pipeline.workspace.min_G, want.workspace.min_G);
  EXPECT_EQ(pipeline.workspace.max_G, want.workspace.max_G);
  EXPECT_EQ(pipeline.num_threads, want.num_threads);
  // The box a null workspace stands for is the library's.
  const RigConfig::Box box;
  EXPECT_EQ(Eigen::Vector3d(box.min_G_m[0], box.min_G_m[1], box.min_G_m[2]), want.workspace.min_G);
  EXPECT_EQ(Eigen::Vector3d(box.max_G_m[0], box.max_G_m[1], box.max_G_m[2]), want.workspace.max_G);

  repair::RepairConfig repair;
  repair.mode = repair::RepairMode::kPaper;
  repair.safe_bound_voxel_m = 0.0;
  repair.top_rim_band_m = 0.0;
  ApplyToRepair(c, &repair);
  const repair::RepairConfig want_repair;
  EXPECT_EQ(repair.mode, want_repair.mode);
  EXPECT_EQ(repair.safe_bound_voxel_m, want_repair.safe_bound_voxel_m);
  EXPECT_EQ(repair.top_rim_band_m, want_repair.top_rim_band_m);
  EXPECT_EQ(repair.num_threads, want_repair.num_threads);

  const io::ChannelNames channels = ToChannelNames(c.channels);
  const io::ChannelNames want_channels;
  EXPECT_EQ(channels.depth, want_channels.depth);
  EXPECT_EQ(channels.gripper_state, want_channels.gripper_state);
  EXPECT_EQ(channels.object_cloud, want_channels.object_cloud);
  EXPECT_EQ(channels.status, want_channels.status);
  EXPECT_EQ(channels.session, want_channels.session);
  EXPECT_EQ(channels.collision_mesh, want_channels.collision_mesh);
  mesh::PlannerMeshConfig planner_mesh;
  planner_mesh.max_triangles = 7;  // must come back as the default's
  planner_mesh.convex_hull = true;
  ApplyToCollisionMesh(c, &planner_mesh);
  EXPECT_EQ(planner_mesh.max_triangles, mesh::PlannerMeshConfig{}.max_triangles);
  EXPECT_FALSE(planner_mesh.convex_hull);

  EXPECT_EQ(c.rates.publish_every_n_frames, GraspModuleConfig{}.extract_every_n_frames);
  EXPECT_EQ(std::lround(c.rates.status_period_s * 1000.0), SessionLoopLimits{}.tick_ms);
  EXPECT_EQ(ClockOffsetUs(c), 0);
  EXPECT_FALSE(IntrinsicsOverride(c).has_value());
  EXPECT_FALSE(c.robot.T_C_B.has_value());
  EXPECT_TRUE(c.claw.spec.empty());
  EXPECT_NO_THROW(c.Validate());
}

TEST(RigConfig, TheSourceOverridesReplaceTheSessionsOnlyWhereTheConfigSetsThem) {
  const SourceOverrides none = ToSourceOverrides(RigConfig{});
  EXPECT_TRUE(none.T_C_B_from_session);
  EXPECT_TRUE(none.intrinsics_from_session);
  EXPECT_FALSE(none.intrinsics.has_value());
  EXPECT_EQ(none.gripper_clock_offset_us, 0);

  const RigConfig c = EveryFieldChanged();
  const SourceOverrides o = ToSourceOverrides(c);
  EXPECT_FALSE(o.T_C_B_from_session);
  EXPECT_TRUE(o.T_C_B.isApprox(c.robot.T_C_B->ToIsometry()));
  EXPECT_NEAR(o.T_C_B.translation().x(), 0.3, 1e-12);
  EXPECT_FALSE(o.intrinsics_from_session);
  ASSERT_TRUE(o.intrinsics.has_value());
  EXPECT_EQ(*o.intrinsics, (CameraIntrinsics{848, 480, 421.1 + 1e-13, 421.3, 424.7, 239.1}));
  EXPECT_EQ(o.gripper_clock_offset_us, -12300);  // -0.0123 s
}

TEST(RigConfig, TheRefineSectionReachesThePipeline) {
  const RigConfig c = ParseRigConfig(
      "refine:\n  enabled: false\n  min_correction_m: 0.001\n  min_correction_deg: 0.25\n"
      "  track_object: true\n  apply_depth_scale: false\ncamera:\n  depth_scale: 1.012\n",
      "refine.yaml");
  PipelineConfig pipeline;
  ApplyToPipeline(c, &pipeline);
  EXPECT_FALSE(pipeline.refine.enabled);
  EXPECT_FALSE(pipeline.refine.apply_depth_scale);
  EXPECT_EQ(pipeline.refine.known_depth_scale, 1.012);
  EXPECT_EQ(pipeline.refine.min_correction_m, 0.001);
  EXPECT_EQ(pipeline.refine.min_correction_deg, 0.25);
  EXPECT_TRUE(pipeline.track_object.enabled);
}

TEST(RigConfig, TheDepthEdgeRejectionCanBeSwitchedOnAndOff) {
  PipelineConfig pipeline;
  ApplyToPipeline(ParseRigConfig("camera:\n  reject_depth_edges: false\n", "edges.yaml"), &pipeline);
  EXPECT_FALSE(pipeline.reject_depth_edges);
  ApplyToPipeline(ParseRigConfig("camera:\n  reject_depth_edges: true\n", "edges.yaml"), &pipeline);
  EXPECT_TRUE(pipeline.reject_depth_edges);
  EXPECT_THROW(ParseRigConfig("camera:\n  reject_depth_edges: 3\n", "edges.yaml"), ConfigError);
}

TEST(RigConfig, TheThreadCountReachesThePipelineAndTheRepair) {
  const RigConfig c = ParseRigConfig("compute:\n  num_threads: 3\n", "threads.yaml");
  PipelineConfig pipeline;
  repair::RepairConfig repair;
  ApplyToPipeline(c, &pipeline);
  ApplyToRepair(c, &repair);
  EXPECT_EQ(pipeline.num_threads, 3);
  EXPECT_EQ(repair.num_threads, 3);
  EXPECT_EQ(ParseRigConfig("compute:\n  num_threads: 0\n", "own.yaml").compute.num_threads, 0);
}

TEST(RigConfig, TheRecordKeepsTheSafeBoundAtTheRepairsVoxel) {
  PipelineConfig pipeline;
  ApplyToPipeline(ParseRigConfig("repair:\n  safe_bound_voxel_m: 0.01\n", "bound.yaml"), &pipeline);
  EXPECT_EQ(pipeline.visibility.safe_bound_voxel_m, 0.01);
  ApplyToPipeline(ParseRigConfig("repair:\n  safe_bound_voxel_m: 0\n", "none.yaml"), &pipeline);
  EXPECT_EQ(pipeline.visibility.safe_bound_voxel_m, 0.0);
  EXPECT_NO_THROW(pipeline.Validate());
}

TEST(RigConfig, DumpThenParseGivesTheSameStruct) {
  const RigConfig defaults;
  EXPECT_EQ(ParseRigConfig(DumpRigConfig(defaults), "defaults.yaml"), defaults);

  const RigConfig changed = EveryFieldChanged();
  ASSERT_NO_THROW(changed.Validate());
  // Every section differs from the defaults, so equality below means each
  // field was written and read back.
  EXPECT_FALSE(changed.camera == defaults.camera);
  EXPECT_FALSE(changed.robot == defaults.robot);
  EXPECT_FALSE(changed.claw == defaults.claw);
  EXPECT_FALSE(changed.workspace == defaults.workspace);
  EXPECT_FALSE(changed.tsdf == defaults.tsdf);
  EXPECT_FALSE(changed.repair == defaults.repair);
  EXPECT_FALSE(changed.refine == defaults.refine);
  EXPECT_FALSE(changed.channels == defaults.channels);
  EXPECT_FALSE(changed.collision_mesh == defaults.collision_mesh);
  EXPECT_FALSE(changed.rates == defaults.rates);
  const std::string text = DumpRigConfig(changed);
  const RigConfig back = ParseRigConfig(text, "changed.yaml");
  EXPECT_EQ(back, changed) << text;
  EXPECT_EQ(back.camera.intrinsics_override->fx_px, 421.1 + 1e-13);  // all digits
  EXPECT_EQ(back.robot.T_C_B->translation_m[0], 0.1 + 0.2);
  EXPECT_EQ(DumpRigConfig(back), text);
}

TEST(RigConfig, TheDumpDocumentsEveryKeyWithItsUnit) {
  const std::string text = DumpRigConfig(RigConfig{});
  for (const char* key : {"device:",
                          "width_px:",
                          "depth_units:",
                          "intrinsics_override: null",
                          "max_depth_pixels: 8388608",
                          "reject_depth_edges: false",
                          "T_C_B: null",
                          "clock_offset_s: 0",
                          "max_pose_gap_s: 0.05",
                          "spec: \"\"",
                          "workspace: null",
                          "voxel_m: null",
                          "sdf_trunc_voxels: 4",
                          "mode: best",
                          "publish_every_n_frames: 30",
                          "status_period_s: 1",
                          "object_cloud: \"GRASPFILL_OBJECT_CLOUD\"",
                          "collision_mesh: \"GRASPFILL_COLLISION_MESH\"",
                          "max_triangles: 5000",
                          "convex_hull: false"}) {
    EXPECT_NE(text.find(key), std::string::npos) << key << "\n" << text;
  }
  // The built-in values the nulls stand for are in the comments.
  EXPECT_NE(text.find("# T_C_B: {translation_m: [0, 0, 0], rotation_wxyz: [1, 0, 0, 0]}"), std::string::npos)
      << text;
  EXPECT_NE(text.find("# workspace: {min_G_m: [-0.1, -0.1, 0.003], max_G_m: [0.1, 0.1, 0.3]}"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("else 0.0015"), std::string::npos) << text;
}

// repair.close_unknown_top closed a top flat at the rim; the top's search
// decides now. A file written before still loads (the key ignored), and a
// value that is not a bool is still an error.
TEST(RigConfig, TheRetiredCloseUnknownTopIsReadAndIgnored) {
  EXPECT_EQ(ParseRigConfig("repair:\n  close_unknown_top: false\n", "old.yaml"), RigConfig{});
  EXPECT_THROW(ParseRigConfig("repair:\n  close_unknown_top: 3\n", "old.yaml"), ConfigError);
}

TEST(RigConfig, AnEmptyOrPartialFileKeepsTheDefaults) {
  EXPECT_EQ(ParseRigConfig("", "empty.yaml"), RigConfig{});
  EXPECT_EQ(ParseRigConfig("# nothing but a comment\n", "comment.yaml"), RigConfig{});
  const RigConfig c = ParseRigConfig(
      "tsdf:\n  voxel_m: 0.002\nrobot:\n  T_C_B:\n    translation_m: [0.1, 0, 0.5]\n"
      "    rotation_wxyz: [0.7071, 0.7071, 0, 0]\n",
      "partial.yaml");
  RigConfig want;
  want.tsdf.voxel_m = 0.002;
  want.robot.T_C_B = RigConfig::Pose{{0.1, 0.0, 0.5}, {0.7071, 0.7071, 0.0, 0.0}};
  EXPECT_EQ(c, want);
  // JSON is YAML too.
  EXPECT_EQ(ParseRigConfig("{\"tsdf\": {\"voxel_m\": 0.002}, \"robot\": {\"T_C_B\": "
                           "{\"translation_m\": [0.1, 0, 0.5], \"rotation_wxyz\": "
                           "[0.7071, 0.7071, 0, 0]}}}",
                           "rig.json"),
            want);
  // A typed (rounded) quaternion is normalized where it is used.
  const Eigen::Isometry3d T = c.robot.T_C_B->ToIsometry();
  EXPECT_NEAR((T.linear() * T.linear().transpose() - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((T.linear() * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-4);
}

struct BadCase {
  std::string yaml;
  std::string field;    ///< ConfigError::field()
  std::string message;  ///< in what(), after "bad.yaml:LINE: "
  int line;
};

TEST(RigConfig, EveryBadValueIsRefusedNamingItsField) {
  const std::vector<BadCase> cases = {
      {"tsdf:\n  voxel_m: 0.002mm\n", "tsdf.voxel_m", "tsdf.voxel_m '0.002mm': not a number", 2},
      {"tsdf:\n  voxel_m: 0.5\n", "tsdf.voxel_m", "tsdf.voxel_m '0.5': out of range, expected 0.0005..0.01 m",
       2},
      {"tsdf:\n  voxel_m: nan\n", "tsdf.voxel_m", "tsdf.voxel_m 'nan': out of range", 2},
      {"tsdf:\n  voxel_m: .nan\n", "tsdf.voxel_m", "tsdf.voxel_m '.nan': not a number", 2},
      {"tsdf:\n  voxel_m: inf\n", "tsdf.voxel_m", "tsdf.voxel_m 'inf': out of range", 2},
      {"tsdf:\n  voxel_m: \" 0.002\"\n", "tsdf.voxel_m",
       "tsdf.voxel_m: expected a number, got the string \" 0.002\"", 2},
      {"tsdf:\n  voxel_m: \"0.002\"\n", "tsdf.voxel_m", "expected a number, got the string", 2},
      {"tsdf:\n  voxel_m: [0.002]\n", "tsdf.voxel_m", "tsdf.voxel_m: expected a number, got a list", 2},
      {"tsdf:\n  voxel_m: 0x10\n", "tsdf.voxel_m", "tsdf.voxel_m '0x10': not a number", 2},
      {"tsdf:\n  voxl_m: 0.002\n", "tsdf.voxl_m", "unknown key 'tsdf.voxl_m' (tsdf has: voxel_m,", 2},
      {"tsdf:\n  block_resolution: 16.5\n", "tsdf.block_resolution",
       "tsdf.block_resolution '16.5': not an integer", 2},
      {"tsdf:\n  block_resolution: 99999999999\n", "tsdf.block_resolution",
       "tsdf.block_resolution '99999999999': out of range, expected 2..128", 2},
      {"tsdf:\n  sdf_trunc_voxels: 1\n", "tsdf.sdf_trunc_voxels", "tsdf.sdf_trunc_voxels '1': out of range",
       2},
      {"tsdf:\n  depth_sampling_stride: 2 # ok\n  depth_sampling_stride: 3\n", "tsdf.depth_sampling_stride",
       "duplicate key 'tsdf.depth_sampling_stride'", 3},
      {"tsdf: 5\n", "tsdf", "tsdf: expected a map of keys, got '5'", 1},
      {"repair:\n  enabled: yes\n", "repair.enabled", "repair.enabled 'yes': expected true or false", 2},
      {"repair:\n  mode: fast\n", "repair.mode", "repair.mode 'fast': expected best or paper", 2},
      {"compute:\n  num_threads: -1\n", "compute.num_threads",
       "compute.num_threads '-1': out of range, expected 0..1024", 2},
      {"compute:\n  num_threads: 2.5\n", "compute.num_threads", "compute.num_threads '2.5': not an integer",
       2},
      {"refine:\n  min_correction_deg: 5\n", "refine.min_correction_deg",
       "refine.min_correction_deg '5': out of range, expected 0..2 deg", 2},
      {"refine:\n  enabled: on\n", "refine.enabled", "refine.enabled 'on': expected true or false", 2},
      {"camera:\n  depth_scale: 1.5\n", "camera.depth_scale",
       "camera.depth_scale '1.5': out of range, expected 0.8..1.25", 2},
      {"repair:\n  safe_bound_voxel_m: 0.0001\n", "repair.safe_bound_voxel_m",
       "expected 0 (no bound) or 0.0005..0.1 m", 2},
      {"robot:\n  clock_offset_s: 1e400\n", "robot.clock_offset_s",
       "robot.clock_offset_s '1e400': out of range, expected -3600..3600 s", 2},
      {"robot:\n  max_pose_gap_s: 0.05s\n", "robot.max_pose_gap_s",
       "robot.max_pose_gap_s '0.05s': not a number", 2},
      {"robot:\n  T_C_B:\n    translation_m: [0, 0]\n    rotation_wxyz: [1, 0, 0, 0]\n",
       "robot.T_C_B.translation_m", "expected a list of 3 numbers, got a list of 2", 3},
      {"robot:\n  T_C_B:\n    translation_m: [0, 0, 1x]\n    rotation_wxyz: [1, 0, 0, 0]\n",
       "robot.T_C_B.translation_m[2]", "robot.T_C_B.translation_m[2] '1x': not a number", 3},
      {"robot:\n  T_C_B:\n    translation_m: [0, 0, 0]\n    rotation_wxyz: [0.5, 0, 0, 0]\n",
       "robot.T_C_B.rotation_wxyz", "robot.T_C_B.rotation_wxyz: not a unit quaternion (norm 0.5", 4},
      {"robot:\n  T_C_B:\n    translation_m: [0, 0, 0]\n", "robot.T_C_B.rotation_wxyz",
       "robot.T_C_B.rotation_wxyz: missing", 3},
      {"workspace:\n  min_G_m: [0, 0, 0.2]\n  max_G_m: [0.1, 0.1, 0.1]\n", "workspace.max_G_m[2]",
       "workspace.max_G_m[2]: must be greater than workspace.min_G_m[2]", 3},
      {"camera:\n  intrinsics_override:\n    width_px: 640\n", "camera.intrinsics_override.height_px",
       "camera.intrinsics_override.height_px: missing", 3},
      {"camera:\n  intrinsics_override: {width_px: 640, height_px: 480, fx_px: 0, fy_px: 1, "
       "cx_px: 1, cy_px: 1}\n",
       "camera.intrinsics_override.fx_px", "camera.intrinsics_override.fx_px '0': out of range", 2},
      {"camera:\n  depth_units: cm\n", "camera.depth_units", "camera.depth_units 'cm': expected mm or 100um",
       2},
      {"camera:\n  fps: -1\n", "camera.fps", "camera.fps '-1': out of range, expected 0..1000", 2},
      {"tsdf:\n  max_fusion_pixels: 100\n", "tsdf.max_fusion_pixels",
       "tsdf.max_fusion_pixels '100': out of range, expected 3072..16777216", 2},
      {"camera:\n  fps: +30\n", "camera.fps", "camera.fps '+30': not an integer", 2},
      {"camera:\n  max_depth_pixels: 16777217\n", "camera.max_depth_pixels",
       "camera.max_depth_pixels '16777217': out of range, expected 1..16777216", 2},
      {"camera:\n  max_depth_pixels: 0\n", "camera.max_depth_pixels",
       "camera.max_depth_pixels '0': out of range", 2},
      {"camera:\n  device: {uri: x}\n", "camera.device", "camera.device: expected a string, got a map", 2},
      {"channels:\n  depth: \"\"\n", "channels.depth", "channels.depth: must not be empty", 2},
      // LCM subscribes to a channel name as a regular expression: "(" would
      // subscribe to nothing, "." to more than the name.
      {"channels:\n  depth: \"GRASPFILL_DEPTH(\"\n", "channels.depth",
       "channels.depth 'GRASPFILL_DEPTH(': '(' is not allowed (channel names are A-Z a-z 0-9 _ - / "
       "only",
       2},
      {"channels:\n  status: A.B\n", "channels.status", "channels.status 'A.B': '.' is not allowed", 2},
      {"channels:\n  object_cloud: \"" + std::string(300, 'C') + "\"\n", "channels.object_cloud",
       "300 characters, over LCM's limit of 63", 2},
      {"collision_mesh:\n  max_triangles: 11\n", "collision_mesh.max_triangles",
       "collision_mesh.max_triangles '11': out of range", 2},
      {"channels:\n  collision_mesh: GRASPFILL_SESSION\n", "channels.collision_mesh",
       "channels.collision_mesh 'GRASPFILL_SESSION': the same name as channels.session", 2},
      {"channels:\n  gripper_state: GRASPFILL_STATUS\n", "channels.gripper_state",
       "channels.gripper_state 'GRASPFILL_STATUS': the same name as channels.status", 2},
      {"rates:\n  publish_every_n_frames: 3.5\n", "rates.publish_every_n_frames",
       "rates.publish_every_n_frames '3.5': not an integer", 2},
      {"rates:\n  status_period_s: 0\n", "rates.status_period_s",
       "rates.status_period_s '0': out of range, expected 0.05..60 s", 2},
      {"camera: {}\ncolour: red\n", "colour", "unknown key 'colour' (the file has: camera,", 2},
      {"- a\n- b\n", "", "the file: expected a map of keys, got a list", 1},
      {"tsdf: {voxel_m: [\n", "", "not YAML", 2},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.yaml);
    try {
      ParseRigConfig(c.yaml, "bad.yaml");
      ADD_FAILURE() << "accepted";
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.field(), c.field) << what;
      EXPECT_EQ(what.rfind("bad.yaml:" + std::to_string(c.line) + ": ", 0), 0u) << what;
      EXPECT_NE(what.find(c.message), std::string::npos) << what;
    }
  }
}

TEST(RigConfig, ChannelNamesAreCheckedAsLcmTakesThem) {
  // 63 characters of every allowed kind: taken; 64: not.
  const std::string longest = "abc-XYZ_0123/" + std::string(50, 'n');
  ASSERT_EQ(longest.size(), 63u);
  EXPECT_EQ(ParseRigConfig("channels:\n  depth: " + longest + "\n", "ok.yaml").channels.depth, longest);
  EXPECT_THROW(ParseRigConfig("channels:\n  depth: " + longest + "x\n", "bad.yaml"), ConfigError);
  // Two the same, both in the file: named at the later one's line.
  try {
    ParseRigConfig("channels:\n  depth: X\n  gripper_state: G\n  status: X\n", "dup.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.field(), "channels.status");
    EXPECT_EQ(std::string(e.what()).rfind("dup.yaml:4: channels.status 'X': the same name as "
                                          "channels.depth",
                                          0),
              0u)
        << e.what();
  }
  // Validate (a struct built in code) checks them too.
  RigConfig c;
  c.channels.session = c.channels.depth;
  try {
    c.Validate();
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.field(), "channels.session");
  }
  c.channels.session = "SESSION (2)";
  EXPECT_THROW(c.Validate(), ConfigError);
}

TEST(RigConfig, ASecondYamlDocumentIsAnError) {
  // yaml-cpp's Load reads the first document and drops the rest: the
  // second one's voxel would be lost without a word.
  try {
    ParseRigConfig("tsdf:\n  voxel_m: 0.002\n---\ntsdf:\n  voxel_m: 0.003\n", "two.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("two.yaml:4: a second YAML document", 0), 0u) << e.what();
  }
  EXPECT_THROW(ParseRigConfig("tsdf: {}\n---\n", "empty_second.yaml"), ConfigError);
  // A document marker at the start is still one document.
  EXPECT_EQ(*ParseRigConfig("---\ntsdf:\n  voxel_m: 0.002\n", "one.yaml").tsdf.voxel_m, 0.002);
}

TEST(RigConfig, DeepNestingIsNamedNotBadFile) {
  for (const std::string& deep : {std::string(5000, '['), "tsdf: " + std::string(3000, '{'), [] {
                                    std::string nested;
                                    for (int i = 0; i < 2500; ++i) nested += std::string(i, ' ') + "a:\n";
                                    return nested;
                                  }()}) {
    try {
      ParseRigConfig(deep, "deep.yaml");
      ADD_FAILURE() << "accepted";
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("nested more than 2000 levels deep"), std::string::npos) << what;
      EXPECT_EQ(what.find("bad file"), std::string::npos) << what;
      EXPECT_EQ(what.rfind("deep.yaml:", 0), 0u) << what;
    }
  }
}

TEST(RigConfig, ValidateNamesTheFieldOfAStructBuiltInCode) {
  RigConfig c;
  c.tsdf.voxel_m = 0.1;
  try {
    c.Validate();
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.field(), "tsdf.voxel_m");
    EXPECT_NE(std::string(e.what()).find("tsdf.voxel_m '0.1': out of range"), std::string::npos);
  }
  RigConfig d;
  d.robot.max_pose_gap_s = std::nan("");
  try {
    d.Validate();
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.field(), "robot.max_pose_gap_s");
  }
}

TEST(RigConfig, LoadNamesAFileItCannotRead) {
  const std::string dir = std::string(GRASPFILL_BINARY_DIR) + "/test_scratch/rig_config_load";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  try {
    LoadRigConfig(dir + "/missing.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot read config '" + dir + "/missing.yaml'"), std::string::npos)
        << e.what();
  }
  // Not a regular file: refused unopened (a FIFO would block the read
  // until a writer came; /dev/zero would never end).
  for (const std::string& special : {dir, std::string("/dev/zero"), std::string("/dev/null")}) {
    try {
      LoadRigConfig(special);
      ADD_FAILURE() << special << " accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("cannot read config '" + special + "': ", 0), 0u) << e.what();
      EXPECT_TRUE(std::string(e.what()).find("not a regular file") != std::string::npos ||
                  std::string(e.what()).find("is a directory") != std::string::npos)
          << e.what();
    }
  }
  const std::string path = dir + "/rig.yaml";
  std::ofstream(path) << "tsdf:\n  voxel_m: 0.003\n";
  EXPECT_EQ(*LoadRigConfig(path).tsdf.voxel_m, 0.003);
  std::ofstream(path) << "tsdf:\n  voxel_m: 0.003 m\n";
  try {
    LoadRigConfig(path);
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ":2: tsdf.voxel_m '0.003 m': not a number", 0), 0u)
        << e.what();
  }
}

}  // namespace
}  // namespace graspfill::rt
