// SPDX-License-Identifier: BSD-3-Clause
#include "synth/scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "graspfill/core/random.hpp"
#include "graspfill/core/require.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "synth/angles.hpp"
#include "synth/finger_touch.hpp"
#include "synth/model_claw_placement.hpp"

namespace graspfill::synth {
namespace {

// Sub-stream of the scene seed for the wobble phases (frames use their
// index, see renderer.cpp, so this sits far from any frame index).
constexpr uint64_t kWobbleStream = 0xfffffffffff0ULL;
// Facets of the arm cylinder: it is background, keep it cheap.
constexpr int kArmSegments = 32;

claw::ClawModel MakeClaw(ClawType type, const claw::ProceduralClawConfig& config) {
  return type == ClawType::kParallel ? claw::ClawModel::Parallel(config)
                                     : claw::ClawModel::ThreeFinger(config);
}

}  // namespace

CameraIntrinsics IntrinsicsAtResolution(int width, int height, const CameraIntrinsics& base) {
  const double sx = static_cast<double>(width) / base.width;
  const double sy = static_cast<double>(height) / base.height;
  CameraIntrinsics K;
  K.width = width;
  K.height = height;
  K.fx = base.fx * sx;
  K.fy = base.fy * sy;
  // Pixel centres: the image's centre stays the centre.
  K.cx = (base.cx + 0.5) * sx - 0.5;
  K.cy = (base.cy + 0.5) * sy - 0.5;
  return K;
}

std::string ClawTypeName(ClawType claw) { return claw == ClawType::kParallel ? "parallel" : "three-finger"; }

std::optional<ClawType> ParseClawType(const std::string& name) {
  if (name == "three-finger") return ClawType::kThreeFinger;
  if (name == "parallel") return ClawType::kParallel;
  return std::nullopt;
}

std::string GraspWayName(GraspWay grasp) {
  switch (grasp) {
    case GraspWay::kTopStraight:
      return "top-straight";
    case GraspWay::kMiddleStraight:
      return "middle-straight";
    case GraspWay::kTopOblique:
      return "top-oblique";
  }
  return "unknown";
}

std::optional<GraspWay> ParseGraspWay(const std::string& name) {
  for (GraspWay g : {GraspWay::kTopStraight, GraspWay::kMiddleStraight, GraspWay::kTopOblique}) {
    if (GraspWayName(g) == name) return g;
  }
  return std::nullopt;
}

Eigen::Vector3d SceneConfig::EffectiveSize() const {
  return (size_m.array() == 0.0).all() ? DefaultSize(shape) : size_m;
}

void SceneConfig::Validate() const {
  if (mesh.empty()) {
    const Eigen::Vector3d size = EffectiveSize();
    Require("SceneConfig", size.allFinite() && (size.array() > 0.0).all(),
            "size_m must be positive (or all zero for the default)");
    Require("SceneConfig", shape_segments >= 8, "shape_segments must be >= 8");
  }
  Require("SceneConfig", num_frames >= 1, "num_frames must be >= 1");
  Require("SceneConfig", depth_rate_hz > 0.0 && gripper_rate_hz > 0.0, "rates must be > 0");
  Require("SceneConfig", gripper_lead_s >= 0.0, "gripper_lead_s must be >= 0");
  Require("SceneConfig",
          intrinsics.width > 0 && intrinsics.height > 0 && intrinsics.fx > 0.0 && intrinsics.fy > 0.0,
          "intrinsics need a positive size and focal length");
  Require(
      "SceneConfig",
      placement.min_palm_gap_m >= 0.0 && placement.finger_pad_m >= 0.0 && placement.finger_clearance_m >= 0.0,
      "placement distances must be >= 0");
  Require("SceneConfig",
          placement.top_contact_fraction > 0.0 && placement.top_contact_fraction < 1.0 &&
              placement.middle_contact_fraction > 0.0 && placement.middle_contact_fraction < 1.0,
          "contact fractions must be in (0, 1)");
  Require("SceneConfig", std::abs(placement.oblique_tilt_deg) < 80.0, "oblique_tilt_deg must be < 80");
  Require("SceneConfig", motion.camera_distance_m > 0.0, "camera_distance_m must be > 0");
  Require("SceneConfig", motion.speed_variation >= 0.0 && motion.speed_variation < 1.0,
          "speed_variation must be in [0, 1)");
  Require("SceneConfig", std::abs(motion.camera_elevation_deg) < 80.0,
          "camera_elevation_deg must be in (-80, 80)");
  Require("SceneConfig",
          environment.wall_distance_m >= 0.0 && environment.arm_radius_m >= 0.0 &&
              environment.arm_length_m >= 0.0,
          "environment distances must be >= 0");
  Require("SceneConfig",
          claw_config.finger_length_m > 0.0 && claw_config.finger_width_m > 0.0 &&
              claw_config.finger_thickness_m > 0.0 && claw_config.palm_thickness_m >= 0.0,
          "claw dimensions must be positive");
  sensor.Validate();
  slip.Validate();
}

Scene::Scene(const SceneConfig& config) : config_(config) {
  config_.Validate();
  object_O_ = config_.mesh.empty() ? MakeShape(config_.shape, config_.EffectiveSize(), config_.shape_segments)
                                   : NormalizeToObjectFrame(config_.mesh);
  const double height = mesh::Bounds(object_O_).sizes().z();
  Require("SceneConfig", height > 0.0, "the object mesh is flat or empty");
  const PlacementConfig& pc = config_.placement;

  // Orientation: up (z_O) to -z_G, then the oblique tilt about G's x.
  const double tilt = config_.grasp == GraspWay::kTopOblique ? pc.oblique_tilt_deg * kDegToRad : 0.0;
  const Eigen::Matrix3d R_G_O =
      (Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  placement_.contact_fraction =
      config_.grasp == GraspWay::kMiddleStraight ? pc.middle_contact_fraction : pc.top_contact_fraction;
  const Eigen::Vector3d contact_O(0.0, 0.0, (1.0 - placement_.contact_fraction) * height);
  const Eigen::Vector3d contact_rot = R_G_O * contact_O;
  if (config_.claw_model) {
    PlaceInModelClaw(R_G_O, contact_rot);
  } else {
    PlaceInBuiltinClaw(R_G_O, contact_rot);
  }
  if (config_.environment.arm_radius_m > 0.0 && config_.environment.arm_length_m > 0.0) {
    MakeArm();
  }
  PlaceCamera();

  Rng rng(DeriveSeed(config_.seed, kWobbleStream));
  for (double& phase : wobble_phase_) phase = 2.0 * M_PI * rng.Uniform();

  slip_ = ObjectSlip(config_.slip, config_.seed, DepthUtime(0), DepthUtime(config_.num_frames - 1));
  object_G_after_slip_ = config_.slip.any() ? object_G_.Transformed(slip_.S_G_final()) : object_G_;
}

// A description or URDF claw keeps its geometry and closes on the object.
void Scene::PlaceInModelClaw(const Eigen::Matrix3d& R_G_O, const Eigen::Vector3d& contact_rot) {
  const ModelClawHold hold =
      HoldInModelClaw(*config_.claw_model, object_O_, R_G_O,
                      Eigen::Vector2d(-contact_rot.x(), -contact_rot.y()), config_.placement.min_palm_gap_m);
  placement_.claw = config_.claw_config;
  placement_.T_G_O = hold.T_G_O;
  placement_.palm_gap_m = hold.palm_gap_m;
  placement_.opening_m = hold.opening;
  object_G_ = object_O_.Transformed(placement_.T_G_O);
  claw_G_ = config_.claw_model->Posed(placement_.opening_m);
}

// A built-in claw: its fingertips below the object's top (fingers
// lengthened when the palm would be too close), the object on G's z axis
// (slid between opposed fingers until both touch), opened to the touch.
void Scene::PlaceInBuiltinClaw(const Eigen::Matrix3d& R_G_O, const Eigen::Vector3d& contact_rot) {
  const PlacementConfig& pc = config_.placement;
  double top_rot = std::numeric_limits<double>::infinity();  // highest point
  for (const Eigen::Vector3f& v : object_O_.vertices) {
    top_rot = std::min(top_rot, (R_G_O * v.cast<double>()).z());
  }
  // Fingertip below the object's top, along G's z.
  const double tip_depth = contact_rot.z() + 0.5 * pc.finger_pad_m - top_rot;
  placement_.claw = config_.claw_config;
  placement_.palm_gap_m = placement_.claw.finger_length_m - tip_depth;
  if (placement_.palm_gap_m < pc.min_palm_gap_m) {
    placement_.palm_gap_m = pc.min_palm_gap_m;
    placement_.claw.finger_length_m = pc.min_palm_gap_m + tip_depth;
  }
  // The contact point sits on G's z axis; the top at the palm gap.
  placement_.T_G_O.linear() = R_G_O;
  placement_.T_G_O.translation() =
      Eigen::Vector3d(-contact_rot.x(), -contact_rot.y(), placement_.palm_gap_m - top_rot);

  const claw::ClawModel probe = MakeClaw(config_.claw, placement_.claw);
  const std::vector<Eigen::Vector3d> dirs = FingerDirections(probe);
  object_G_ = object_O_.Transformed(placement_.T_G_O);
  placement_.finger_touch_radius_m =
      FingerTouchRadii(object_G_, dirs, placement_.claw.finger_width_m, placement_.claw.finger_length_m);
  std::vector<double>& radii = placement_.finger_touch_radius_m;
  for (size_t i = 0; i < radii.size(); ++i) {
    if (!std::isfinite(radii[i])) {
      throw std::invalid_argument("Scene: finger " + std::to_string(i) + " does not reach the object");
    }
  }
  if (dirs.size() == 2 && dirs[0].dot(dirs[1]) < -0.999) {
    // Opposed fingers close until both touch: slide the object along d0.
    // The footprints do not depend on this slide, so one step is exact.
    const double shift = 0.5 * (radii[1] - radii[0]);
    placement_.T_G_O.pretranslate(shift * dirs[0]);
    object_G_ = object_O_.Transformed(placement_.T_G_O);
    radii =
        FingerTouchRadii(object_G_, dirs, placement_.claw.finger_width_m, placement_.claw.finger_length_m);
  }
  placement_.opening_m = *std::max_element(radii.begin(), radii.end()) + pc.finger_clearance_m;
  Require("SceneConfig", placement_.opening_m > 0.0, "the object is too thin for the claw");
  // Keep the claw's joint limits from clamping the opening we need.
  placement_.claw.max_opening_m = std::max(placement_.claw.max_opening_m, placement_.opening_m);
  placement_.claw.min_opening_m = std::min(placement_.claw.min_opening_m, placement_.opening_m);
  claw_G_ = MakeClawModel().Posed(placement_.opening_m);
}

// The robot's arm: a cylinder behind the palm, along G's z.
void Scene::MakeArm() {
  const double r = config_.environment.arm_radius_m;
  const double len = config_.environment.arm_length_m;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  // Behind the palm: a model claw's back is its lowest point.
  const double palm_back_m =
      config_.claw_model ? -mesh::Bounds(claw_G_).min().z() : placement_.claw.palm_thickness_m;
  T.translation().z() = -palm_back_m - len;
  arm_G_ = MakeShape(Shape::kCylinder, Eigen::Vector3d(2 * r, 2 * r, len), kArmSegments).Transformed(T);
}

// Camera: at the object's centre's level minus the elevation, looking at
// it; optical frame x right, y down, z forward.
void Scene::PlaceCamera() {
  const Eigen::AlignedBox3d box_G = mesh::Bounds(object_G_);
  centre_G_ = Eigen::Vector3d(0.0, 0.0, box_G.center().z());
  const double e = config_.motion.camera_elevation_deg * kDegToRad;
  const Eigen::Vector3d forward(std::cos(e), 0.0, std::sin(e));
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  T_W_C_.linear().col(0) = right;
  T_W_C_.linear().col(1) = down;
  T_W_C_.linear().col(2) = forward;
  T_W_C_.translation() = -config_.motion.camera_distance_m * forward;
}

claw::ClawModel Scene::MakeClawModel() const {
  if (config_.claw_model) return *config_.claw_model;
  return MakeClaw(config_.claw, placement_.claw);
}

Eigen::AlignedBox3d Scene::WorkspaceBoxG(double margin_m) const {
  Eigen::AlignedBox3d box = mesh::Bounds(object_G_);
  box.min().array() -= margin_m;
  box.max().array() += margin_m;
  box.min().z() = std::max(box.min().z(), 0.0);
  return box;
}

Eigen::Isometry3d Scene::T_W_G(double t_s) const {
  const double duration_s = config_.num_frames / config_.depth_rate_hz;
  double s = t_s / duration_s;
  if (config_.motion.speed_variation != 0.0) {
    s -= config_.motion.speed_variation * std::sin(2.0 * M_PI * s) / (2.0 * M_PI);
  }
  const double theta = 2.0 * M_PI * config_.motion.turns * s;
  // Slow, incommensurate frequencies: a smooth wobble that 100 Hz states
  // sample densely enough for slerp.
  const double a = config_.motion.wobble_deg * kDegToRad;
  const double w = config_.motion.wobble_translation_m;
  const double* ph = wobble_phase_;
  const Eigen::Matrix3d R_wobble =
      (Eigen::AngleAxisd(a * std::sin(2.0 * M_PI * 0.37 * t_s + ph[0]), Eigen::Vector3d::UnitX()) *
       Eigen::AngleAxisd(a * std::sin(2.0 * M_PI * 0.23 * t_s + ph[1]), Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  const Eigen::Vector3d p_wobble(w * std::sin(2.0 * M_PI * 0.29 * t_s + ph[2]),
                                 w * std::sin(2.0 * M_PI * 0.41 * t_s + ph[0] + 1.0),
                                 w * std::sin(2.0 * M_PI * 0.17 * t_s + ph[1] + 2.0));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R_wobble * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix() *
               Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  // The turn axis (G's z) passes through the object's centre at W's origin.
  T.translation() = -(T.linear() * centre_G_) + p_wobble;
  return T;
}

Eigen::Isometry3d Scene::T_C_G(double t_s) const { return T_W_C_.inverse() * T_W_G(t_s); }

Eigen::Isometry3d Scene::T_C_G_AtUtime(int64_t utime) const {
  return T_C_G(static_cast<double>(utime - config_.motion.start_utime) * 1e-6);
}

int64_t Scene::DepthUtime(int frame_index) const {
  return config_.motion.start_utime + std::llround(frame_index * 1e6 / config_.depth_rate_hz);
}

std::vector<int64_t> Scene::DepthUtimes() const {
  std::vector<int64_t> utimes;
  for (int i = 0; i < config_.num_frames; ++i) utimes.push_back(DepthUtime(i));
  return utimes;
}

std::vector<int64_t> Scene::GripperUtimes() const {
  const int64_t lead_us = std::llround(config_.gripper_lead_s * 1e6);
  const int64_t first = config_.motion.start_utime - lead_us + config_.gripper_offset_us;
  const int64_t last = DepthUtime(config_.num_frames - 1) + lead_us;
  std::vector<int64_t> utimes;
  for (int64_t k = 0;; ++k) {
    const int64_t utime = first + std::llround(static_cast<double>(k) * 1e6 / config_.gripper_rate_hz);
    if (utime > last) break;
    utimes.push_back(utime);
  }
  return utimes;
}

GripperState Scene::GripperStateAt(int64_t utime) const {
  GripperState state;
  state.utime = utime;
  state.T_C_G = T_C_G_AtUtime(utime);
  state.opening_m = placement_.opening_m;
  return state;
}

std::vector<TimelineEvent> Scene::Timeline() const {
  std::vector<TimelineEvent> events;
  const std::vector<int64_t> depth = DepthUtimes();
  const std::vector<int64_t> gripper = GripperUtimes();
  for (size_t i = 0; i < depth.size(); ++i) {
    events.push_back({depth[i], TimelineEvent::Kind::kDepth, static_cast<int>(i)});
  }
  for (size_t i = 0; i < gripper.size(); ++i) {
    events.push_back({gripper[i], TimelineEvent::Kind::kGripperState, static_cast<int>(i)});
  }
  std::stable_sort(events.begin(), events.end(),
                   [](const TimelineEvent& a, const TimelineEvent& b) { return a.utime < b.utime; });
  return events;
}

}  // namespace graspfill::synth
