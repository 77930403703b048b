// SPDX-License-Identifier: BSD-3-Clause
// A synthetic grasp scene: an object held by a procedural claw, turned one
// full revolution in front of a fixed depth camera. Everything is defined
// in the gripper frame G (see types.hpp) and is a pure function of the
// SceneConfig, so a scene can be rebuilt from its scene.json.
//
// Placement rule (built-in shapes and user meshes alike):
//  - The object's up (+z of frame O) points to the palm: z_O maps to -z_G
//    (a half turn about x), so the object's top faces the palm and its
//    bottom faces away, along the approach direction.
//  - Straight grasps keep the object's axis on G's z axis; the oblique
//    grasp then tilts the object by `oblique_tilt_deg` about G's x.
//  - Contact height: the fingers' pads (length `finger_pad_m`, ending at the
//    fingertips) are centred at `contact_fraction * H` below the object's
//    top along its axis (top grasps 25 %, middle 50 %).
//  - The claw keeps its own finger length; the object hangs so that the
//    fingertips reach the contact height, i.e. the gap between the palm face
//    and the object's highest point follows from it. If that gap would be
//    below `min_palm_gap_m`, the gap is clamped and the fingers lengthened
//    (recorded in Placement::claw).
//  - Opening: for every finger, the largest radial extent of the object
//    within the finger's footprint (its width times its length, exact
//    triangle clipping) plus `finger_clearance_m`; the claw takes the
//    largest over its fingers, so the widest-reaching finger touches and no
//    finger penetrates. A two-finger (parallel) claw first slides the object
//    along the fingers' line until both fingers touch (self-centring).
//
// Motion: world W has z up; the camera looks at the object's centre from
// `camera_distance_m`, `camera_elevation_deg` below it, so it sees the
// object's bottom but never its top. The gripper points down (z_G = -z_W)
// and turns `turns` revolutions about its z axis over the recording, at a
// constant rate unless `speed_variation` is set, with a small smooth wobble.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "graspfill/claw/claw_model.hpp"
#include "graspfill/types.hpp"
#include "synth/object_slip.hpp"
#include "synth/sensor_model.hpp"
#include "synth/shapes.hpp"

namespace graspfill::synth {

/// Default size of a scene's ground-truth cloud (points sampled on its
/// object_G()): 100k points, i.e. ~0.7 mm mean spacing on the default
/// 7 x 7 x 14 cm cuboid (490 cm^2).
constexpr int kDefaultGroundTruthPoints = 100000;

enum class ClawType { kThreeFinger, kParallel };
/// The paper's three grasping ways (section 3.1.3).
enum class GraspWay { kTopStraight, kMiddleStraight, kTopOblique };

/// "three-finger" / "parallel".
/// `base`'s field of view at another resolution (e.g. a 4096 x 4096
/// stream): focal lengths and principal point scaled per axis.
CameraIntrinsics IntrinsicsAtResolution(int width, int height,
                                        const CameraIntrinsics& base = CameraIntrinsics{});

std::string ClawTypeName(ClawType claw);
std::optional<ClawType> ParseClawType(const std::string& name);
/// "top-straight" / "middle-straight" / "top-oblique".
std::string GraspWayName(GraspWay grasp);
std::optional<GraspWay> ParseGraspWay(const std::string& name);

/// How the object sits in the claw (see the file comment for the rule).
struct PlacementConfig {
  double min_palm_gap_m{0.005};         ///< palm face to the object's top
  double top_contact_fraction{0.25};    ///< of H below the top, top grasps
  double middle_contact_fraction{0.5};  ///< of H below the top, middle grasp
  double finger_pad_m{0.02};            ///< contact length at the fingertip
  double oblique_tilt_deg{20.0};        ///< about G's x, oblique grasp
  double finger_clearance_m{0.0005};    ///< gap left by the closest finger
};

/// Camera placement and the gripper's trajectory.
struct MotionConfig {
  double camera_distance_m{0.55};     ///< camera to the object's centre
  double camera_elevation_deg{25.0};  ///< camera below the object, looking up
  double turns{1.0};                  ///< revolutions over the recording
  /// The turn's speed varies by this share of its mean, once over the
  /// recording: angle(s) = turns * 2 pi * (s - F sin(2 pi s) / (2 pi)),
  /// s in [0, 1], speed (1 - F cos(2 pi s)) x the mean; 0 (the default):
  /// a steady turn. A real arm accelerates and brakes; a clock offset is
  /// separable from a hand-eye rotation only then (docs/imperfect-robots.md).
  double speed_variation{0.0};
  double wobble_deg{1.0};                 ///< amplitude of the approach-axis tilt
  double wobble_translation_m{0.002};     ///< amplitude of the position wobble
  int64_t start_utime{1700000000000000};  ///< first depth frame [us]
};

/// What else the camera sees.
struct EnvironmentConfig {
  /// A wall perpendicular to the optical axis at this z in C [m]; 0: none.
  double wall_distance_m{1.4};
  /// The robot arm: a cylinder behind the palm along -z_G [m].
  double arm_radius_m{0.035};
  double arm_length_m{0.3};
};

/// Everything a synthetic recording is made from. Sizes in meters.
struct SceneConfig {
  Shape shape{Shape::kCuboid};
  /// Bounding box W x D x H [m]; zero means DefaultSize(shape).
  Eigen::Vector3d size_m{0.0, 0.0, 0.0};
  /// A user mesh replacing `shape` when non-empty (meters, +z up; moved
  /// into frame O by NormalizeToObjectFrame). `mesh_name` is informational.
  TriangleMesh mesh;
  std::string mesh_name;
  int shape_segments{128};  ///< facets around curved shapes

  ClawType claw{ClawType::kThreeFinger};
  claw::ProceduralClawConfig claw_config;  ///< the claw's dimensions
  /// A description or URDF claw replacing `claw` and `claw_config` when set,
  /// placed by the rule in model_claw_placement.hpp.
  std::shared_ptr<const claw::ClawModel> claw_model;
  GraspWay grasp{GraspWay::kTopStraight};

  uint64_t seed{1};    ///< sensor noise, wobble phases
  int num_frames{90};  ///< 90 = one turn in 3 s at 30 Hz
  double depth_rate_hz{30.0};
  double gripper_rate_hz{100.0};
  /// Gripper states are shifted by this from the depth frames' clock so
  /// that the two streams never align [us].
  int64_t gripper_offset_us{3700};
  /// Gripper states start this long before the first depth frame and end
  /// this long after the last one, so every frame is bracketed [s].
  double gripper_lead_s{0.1};

  CameraIntrinsics intrinsics;
  SensorModelConfig sensor;
  PlacementConfig placement;
  MotionConfig motion;
  EnvironmentConfig environment;
  /// The object sliding in the grasp (seeded by `seed`; none by default).
  SlipConfig slip;

  /// Size actually used (size_m, or the default for the shape).
  Eigen::Vector3d EffectiveSize() const;
  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

/// Derived placement of the object and the claw.
struct Placement {
  Eigen::Isometry3d T_G_O{Eigen::Isometry3d::Identity()};  ///< object in G
  double palm_gap_m{0.0};                                  ///< palm face (z = 0) to the object's top
  double contact_fraction{0.0};
  double opening_m{0.0};  ///< the claw's opening (finger inner radius;
                          ///< a model claw's own units)
  /// Per finger: radius at which it would touch the object [m].
  std::vector<double> finger_touch_radius_m;
  claw::ProceduralClawConfig claw;  ///< the claw as used (finger length)
};

/// What a recording holds, in time order.
struct TimelineEvent {
  enum class Kind { kDepth, kGripperState };
  int64_t utime{0};
  Kind kind{Kind::kDepth};
  int index{0};  ///< frame index or gripper-state index
};

class Scene {
 public:
  /// Builds the meshes and the placement. Throws std::invalid_argument on
  /// a bad config or an object the claw cannot hold.
  explicit Scene(const SceneConfig& config);

  const SceneConfig& config() const { return config_; }
  const Placement& placement() const { return placement_; }
  /// The object in its own frame O, and in G.
  const TriangleMesh& object_O() const { return object_O_; }
  const TriangleMesh& object_G() const { return object_G_; }
  /// The slip (identity motion without one) and the object where it ends,
  /// in G (object_G() without slip).
  const ObjectSlip& slip() const { return slip_; }
  const TriangleMesh& object_G_after_slip() const { return object_G_after_slip_; }
  /// The object's motion in G at `utime` (ObjectSlip::S_G).
  Eigen::Isometry3d ObjectSlipAt(int64_t utime) const { return slip_.S_G(utime); }
  /// The posed claw (palm and fingers) in G.
  const TriangleMesh& claw_G() const { return claw_G_; }
  /// The robot arm behind the palm, in G.
  const TriangleMesh& arm_G() const { return arm_G_; }
  /// The claw model with Placement::claw's dimensions.
  claw::ClawModel MakeClawModel() const;

  /// Object bounding box in G grown by `margin_m`, cut at the palm face
  /// (z >= 0): the region a TSDF must cover.
  Eigen::AlignedBox3d WorkspaceBoxG(double margin_m = 0.02) const;

  /// Camera pose in the world (z up, origin at the object's centre).
  Eigen::Isometry3d T_W_C() const { return T_W_C_; }
  /// Gripper pose in the world at `t_s` seconds after the first frame.
  Eigen::Isometry3d T_W_G(double t_s) const;
  /// Gripper pose in the camera at `t_s` seconds after the first frame.
  Eigen::Isometry3d T_C_G(double t_s) const;
  /// Same at an absolute timestamp [us].
  Eigen::Isometry3d T_C_G_AtUtime(int64_t utime) const;

  int num_frames() const { return config_.num_frames; }
  int64_t DepthUtime(int frame_index) const;
  std::vector<int64_t> DepthUtimes() const;
  std::vector<int64_t> GripperUtimes() const;
  /// The gripper state a robot would publish at `utime`.
  GripperState GripperStateAt(int64_t utime) const;
  /// Depth frames and gripper states merged in time order (a depth frame
  /// first on a tie, which the default offset never produces).
  std::vector<TimelineEvent> Timeline() const;

 private:
  // The constructor's steps: the object placed in the claw (config_'s
  // model or built-in), the arm behind it, the camera looking at it.
  void PlaceInModelClaw(const Eigen::Matrix3d& R_G_O, const Eigen::Vector3d& contact_rot);
  void PlaceInBuiltinClaw(const Eigen::Matrix3d& R_G_O, const Eigen::Vector3d& contact_rot);
  void MakeArm();
  void PlaceCamera();

  SceneConfig config_;
  TriangleMesh object_O_;
  TriangleMesh object_G_;
  TriangleMesh object_G_after_slip_;
  ObjectSlip slip_;
  TriangleMesh claw_G_;
  TriangleMesh arm_G_;
  Placement placement_;
  Eigen::Isometry3d T_W_C_{Eigen::Isometry3d::Identity()};
  Eigen::Vector3d centre_G_{0.0, 0.0, 0.0};  ///< rotation centre on G's z
  double wobble_phase_[3]{0.0, 0.0, 0.0};
};

}  // namespace graspfill::synth
