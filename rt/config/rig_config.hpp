// SPDX-License-Identifier: BSD-3-Clause
// One config for a rig (issue 8, item 5): the camera, the robot (hand-eye,
// clock), the claw, the workspace box, the TSDF, the repair, the LCM
// channels and the rates, in one YAML file that `graspfill replay` and
// `graspfill live` take with --config FILE (`graspfill config
// --dump-defaults` writes the defaults, each documented).
//
// Plain structs with their defaults in-class, units in the names (_m, _s,
// _px); a member that is std::optional and empty ("null" in the file) is
// taken from the recording's (or the bus's) session description, else the
// built-in default its comment names. Precedence, lowest first: the
// defaults, the session description, this file, explicit command-line flags
// (docs/rig-config.md).
//
// Parsing is strict: every number is the whole scalar, finite and in its
// field's range (no trailing text, no quotes, no NaN); a key the file does
// not know, a duplicate key, or a value of the wrong type is an error that
// names the file, the line and the field (e.g. `rig.yaml:7: tsdf.voxel_m
// '0.5': out of range, expected 0.0005..0.01 m`). YAML and file formats stay
// here in rt/: the algorithm libraries only see the structs they always had
// (PipelineConfig, repair::RepairConfig, ...), filled by the Apply* helpers.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "graspfill/io/messages.hpp"
#include "graspfill/types.hpp"
#include "sources/session_overrides.hpp"

namespace graspfill {
struct PipelineConfig;  // graspfill/pipeline/pipeline.hpp
namespace repair {
struct RepairConfig;  // graspfill/repair/repairer.hpp
}  // namespace repair
namespace mesh {
struct PlannerMeshConfig;  // graspfill/mesh/planner_mesh.hpp
}  // namespace mesh
}  // namespace graspfill

namespace graspfill::rt {

/// A bad config: what() names the file (when read from one), the line and
/// the field; field() is the field's dotted path alone (e.g.
/// "robot.T_C_B.rotation_wxyz[0]", or "tsdf.voxl_m" for an unknown key).
class ConfigError : public std::runtime_error {
 public:
  ConfigError(std::string field, const std::string& message)
      : std::runtime_error(message), field_(std::move(field)) {}
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

struct RigConfig {
  /// Pinhole intrinsics used instead of the depth images' own, for images
  /// of width_px x height_px (with an OpenNI2 device: fx, fy, cx, cy replace
  /// the device's).
  struct Intrinsics {
    int width_px{640};
    int height_px{480};
    double fx_px{525.0};
    double fy_px{525.0};
    double cx_px{319.5};
    double cy_px{239.5};
    bool operator==(const Intrinsics& o) const;
  };
  struct Camera {
    /// OpenNI2 device URI, an .oni file or graspfill-replay:LOG; "" = any
    /// device (`live` without --depth-from-lcm).
    std::string device;
    /// Video mode asked of the device; 0 = the device's own.
    int width_px{0};
    int height_px{0};
    int fps{0};
    /// Depth units asked of the device: "mm" or "100um".
    std::string depth_units{"mm"};
    /// none = the session description's override, else the images' own.
    std::optional<Intrinsics> intrinsics_override;
    /// Depth images (bus, log) with more pixels are refused before they are
    /// decoded (counted as bad_size): 1..2^24; 2^23 (8 MP) by default, room
    /// for the largest common depth sensors (~5 MP) (io::kDefaultMaxDepthPixels).
    int max_depth_pixels{static_cast<int>(io::kDefaultMaxDepthPixels)};
    /// Drop the pixels on depth edges before fusion: mixed (flying) pixels
    /// and the silhouette's grazing returns (fusion/depth_edges.hpp).
    bool reject_depth_edges{false};
    /// The sensor's depth is this many times the true one (a calibration,
    /// e.g. the factor a replay reported in refine.depth_scale): frames are
    /// divided by it from the first. 0.8..1.25.
    double depth_scale{1.0};
    bool operator==(const Camera& o) const;
  };
  /// A rigid transform: p_C = R(rotation_wxyz) * p_B + translation_m.
  struct Pose {
    std::array<double, 3> translation_m{0.0, 0.0, 0.0};
    /// Unit quaternion (w, x, y, z); normalized when used.
    std::array<double, 4> rotation_wxyz{1.0, 0.0, 0.0, 0.0};
    Eigen::Isometry3d ToIsometry() const;
    bool operator==(const Pose& o) const;
  };
  struct Robot {
    /// Hand-eye calibration T_C_B: maps points from the robot base B to the
    /// camera C, for gripper states sent in the base frame. none = the
    /// session description's, else identity.
    std::optional<Pose> T_C_B;
    /// Added to every gripper state's stamp: the robot's clock onto the
    /// camera's [s] (0: one clock).
    double clock_offset_s{0.0};
    /// Gripper states bracketing a depth frame at most this far apart [s].
    double max_pose_gap_s{0.05};
    bool operator==(const Robot& o) const;
  };
  struct Claw {
    /// three-finger, parallel, a description .json, a .urdf or a URDF
    /// config .json; "" = the session description's claw, else three-finger.
    std::string spec;
    /// Where the description's or URDF's meshes are ("" = beside it).
    std::string mesh_root;
    bool operator==(const Claw& o) const;
  };
  /// The object's box in the gripper frame G [m].
  struct Box {
    std::array<double, 3> min_G_m{-0.10, -0.10, 0.003};
    std::array<double, 3> max_G_m{0.10, 0.10, 0.30};
    bool operator==(const Box& o) const;
  };
  struct Tsdf {
    /// Voxel edge [m]; none = the session description's, else 0.0015.
    std::optional<double> voxel_m;
    /// Truncation distance in voxels (sdf_trunc = this x voxel_m).
    double sdf_trunc_voxels{4.0};
    /// Open3D's voxel block edge [voxels].
    int block_resolution{16};
    /// Every Nth pixel of each row and column is integrated.
    int depth_sampling_stride{2};
    /// Frames with more pixels than this are fused decimated (every f-th
    /// pixel and row; PipelineConfig::max_fusion_pixels).
    int max_fusion_pixels{1280 * 1024};
    bool operator==(const Tsdf& o) const;
  };
  struct Repair {
    /// Repair the fused cloud before it is written / published.
    bool enabled{true};
    /// "best" (graspfill's) or "paper" (the method as published).
    std::string mode{"best"};
    /// Use what the camera saw (the visibility record) in the repair.
    bool use_evidence{true};
    /// The planner's safe bound's voxel edge [m]; 0 = no bound.
    double safe_bound_voxel_m{0.005};
    /// Boundary points this close to the top form the rim [m] (best mode).
    double top_rim_band_m{0.004};
    /// Live: update the last full repair between full repairs (false: a
    /// full repair per published cloud).
    bool incremental{true};
    bool operator==(const Repair& o) const;
  };
  /// Pose refinement (PipelineConfig::refine, ::track_object).
  struct Refine {
    /// Correct each frame's gripper pose by registering the claw model to
    /// the depth (false: fuse at the logged poses).
    bool enabled{true};
    /// Corrections beyond the prediction smaller than both are not fused:
    /// the registration's jitter [m], [deg].
    double min_correction_m{0.0005};
    double min_correction_deg{0.5};
    /// Follow the object slipping in the grasp (frame-to-model tracking).
    bool track_object{false};
    /// Divide the depth by the scale error the claw's size shows, once
    /// confident (false: only reported).
    bool apply_depth_scale{true};
    bool operator==(const Refine& o) const;
  };
  /// LCM channel names: each 1..63 characters of A-Z a-z 0-9 _ - /, no
  /// two the same (io/channel_names.hpp says why).
  struct Channels {
    std::string depth{"GRASPFILL_DEPTH"};
    std::string gripper_state{"GRASPFILL_GRIPPER_STATE"};
    std::string object_cloud{"GRASPFILL_OBJECT_CLOUD"};
    std::string status{"GRASPFILL_STATUS"};
    std::string session{"GRASPFILL_SESSION"};
    std::string collision_mesh{"GRASPFILL_COLLISION_MESH"};
    bool operator==(const Channels& o) const;
  };
  /// The collision mesh for the planner (`replay --mesh-out`;
  /// mesh/planner_mesh.hpp).
  struct CollisionMesh {
    /// At most this many triangles (--mesh-max-triangles), 12..10,000,000.
    int max_triangles{5000};
    /// The convex hull instead of the decimated shape (--mesh-convex-hull).
    bool convex_hull{false};
    bool operator==(const CollisionMesh& o) const;
  };
  struct Rates {
    /// `live`: publish the cloud every N fused frames (0: only at each
    /// grasp's end).
    int publish_every_n_frames{30};
    /// `live`: the module status's period [s].
    double status_period_s{1.0};
    bool operator==(const Rates& o) const;
  };

  /// The OpenMP threads of the pipeline's and the repair's calls
  /// (PipelineConfig::num_threads, RepairConfig::num_threads).
  struct Compute {
    /// 1: each call on its own thread alone; N: at most N; 0: OpenMP's own
    /// count (a thread per core).
    int num_threads{1};
    bool operator==(const Compute& o) const;
  };

  Camera camera;
  Robot robot;
  Claw claw;
  /// none = the session description's box, else the default Box above.
  std::optional<Box> workspace;
  Tsdf tsdf;
  Repair repair;
  Refine refine;
  Channels channels;
  CollisionMesh collision_mesh;
  Rates rates;
  Compute compute;

  bool operator==(const RigConfig& o) const;
  bool operator!=(const RigConfig& o) const { return !(*this == o); }

  /// Every field in its range (the ranges the file's parser enforces).
  /// @throws ConfigError naming the first bad field.
  void Validate() const;
};

/// The config as YAML, every field with a comment saying what it is, its
/// unit and default; an empty optional is written `null`, with the
/// built-in default it stands for commented above it. ParseRigConfig of the
/// text gives `config` back exactly (numbers are written shortest
/// round-trip).
std::string DumpRigConfig(const RigConfig& config);

/// Parses YAML text (an empty document: all defaults). `name` (the file's
/// path) prefixes the messages. Keys left out keep their defaults.
/// @throws ConfigError naming `name`, the line and the field: YAML syntax,
///   an unknown or duplicate key, a value of the wrong kind (a map for a
///   number, a quoted number, "yes" for a boolean), a number with trailing
///   text, NaN or out of range, a bad enum value, a box with min >= max, a
///   quaternion that is not unit length, a channel name LCM would not
///   take as it is or two channels of one name, a second YAML document, YAML
///   nested beyond yaml-cpp's 2000 levels.
RigConfig ParseRigConfig(const std::string& text, const std::string& name);

/// Reads and parses `path`: a regular file of at most 1 MiB (a FIFO or a
/// device is refused unopened: it could block or never end).
/// @throws ConfigError as ParseRigConfig, and "cannot read config '<path>':
///   <reason>" when the file cannot be read.
RigConfig LoadRigConfig(const std::string& path);

// ---- onto the existing config structs ----

/// The TSDF voxel edge and truncation, workspace box (when the config has
/// one), pose gap and threads. The voxel only when tsdf.voxel_m is set: otherwise
/// the truncation is sdf_trunc_voxels x the voxel already in `pipeline`.
void ApplyToPipeline(const RigConfig& config, PipelineConfig* pipeline);
/// mode, safe bound, rim band, threads.
void ApplyToRepair(const RigConfig& config, repair::RepairConfig* repair);
/// max_triangles, convex_hull.
void ApplyToCollisionMesh(const RigConfig& config, mesh::PlannerMeshConfig* mesh);
io::ChannelNames ToChannelNames(const RigConfig::Channels& channels);
/// The override as CameraIntrinsics, or none.
std::optional<CameraIntrinsics> IntrinsicsOverride(const RigConfig& config);
/// robot.clock_offset_s in microseconds (rounded).
int64_t ClockOffsetUs(const RigConfig& config);
/// robot.T_C_B and the intrinsics override, each over the session
/// descriptions' when the config has it, and the clock offset.
SourceOverrides ToSourceOverrides(const RigConfig& config);

}  // namespace graspfill::rt
