// SPDX-License-Identifier: BSD-3-Clause
#include "synth/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "graspfill/core/random.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"

namespace graspfill::synth {
namespace {

// Pixels added around the projected bounding box (rounding, safety).
constexpr int kRoiMarginPx = 2;
// Corners nearer than this in C make the projection unusable: cast all.
constexpr double kMinProjectionDepthM = 1e-3;

// Lays the object's pixels over the rest where they are nearer.
void OverlayNearer(const IdealDepthImage& object, IdealDepthImage* image) {
  if (!object.unlit.empty() && image->unlit.empty()) image->unlit.assign(image->depth_m.size(), kLit);
  for (size_t i = 0; i < object.depth_m.size(); ++i) {
    if (object.label[i] != SurfaceLabel::kObject) continue;
    if (image->label[i] != SurfaceLabel::kNone && !(object.depth_m[i] < image->depth_m[i])) {
      continue;
    }
    image->depth_m[i] = object.depth_m[i];
    image->cos_incidence[i] = object.cos_incidence[i];
    image->label[i] = SurfaceLabel::kObject;
    if (!object.unlit.empty()) image->unlit[i] = object.unlit[i];
  }
}

// A smooth random field in [0, 1) over 3D space: uniform values on a
// lattice of `cell_m` (hashed from the cell and the seed), blended by
// smoothstep weights; the blobs above a threshold are the dark patches.
double UnitHash(int64_t x, int64_t y, int64_t z, uint64_t seed) {
  uint64_t h = seed ^ (static_cast<uint64_t>(x) * 0x9E3779B97F4A7C15ull);
  h ^= static_cast<uint64_t>(y) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
  h ^= static_cast<uint64_t>(z) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
  return static_cast<double>(SplitMix64(h) >> 11) * 0x1.0p-53;
}

double PatchField(const Eigen::Vector3d& p, double cell_m, uint64_t seed) {
  // The lattice turned off the axes: a face along them would cut it at one
  // depth in every cell, where the blend's spread differs from the mean.
  static const Eigen::Matrix3d kTurn =
      Eigen::AngleAxisd(1.0, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  const Eigen::Vector3d q = kTurn * p / cell_m;
  const Eigen::Vector3d f = q.array().floor();
  const Eigen::Vector3d t = q - f;
  const Eigen::Vector3d w = t.array() * t.array() * (3.0 - 2.0 * t.array());
  const int64_t x = static_cast<int64_t>(f.x()), y = static_cast<int64_t>(f.y()),
                z = static_cast<int64_t>(f.z());
  double value = 0.0;
  for (int k = 0; k < 8; ++k) {
    const int dx = k & 1, dy = (k >> 1) & 1, dz = (k >> 2) & 1;
    const double weight =
        (dx ? w.x() : 1.0 - w.x()) * (dy ? w.y() : 1.0 - w.y()) * (dz ? w.z() : 1.0 - w.z());
    value += weight * UnitHash(x + dx, y + dy, z + dz, seed);
  }
  return value;
}

// The value of the field that `share` of space lies above, from a
// deterministic sample of it.
double PatchThreshold(double share, uint64_t seed) {
  constexpr int kSamples = 20000;
  Rng rng(seed ^ 0x5DEECE66Dull);
  std::vector<double> values(kSamples);
  for (double& v : values) {
    const Eigen::Vector3d p(64.0 * rng.Uniform(), 64.0 * rng.Uniform(), 64.0 * rng.Uniform());
    v = PatchField(p, 1.0, seed);
  }
  const auto at = values.begin() + static_cast<long>((1.0 - share) * (kSamples - 1));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

// Points this far along a shadow ray from the surface are its own.
constexpr float kShadowOffsetM = 0.0005f;

}  // namespace

void DepthRenderer::SetUnlit(const SensorModelConfig& sensor, uint64_t seed) {
  projector_shadow_ = sensor.projector_shadow;
  projector_C_ = Eigen::Vector3d(sensor.baseline_m, 0.0, 0.0);
  patch_share_ = sensor.dark_patch_share;
  patch_cell_m_ = sensor.dark_patch_size_m;
  patch_seed_ = seed;
  patch_threshold_ = patch_share_ > 0.0 ? PatchThreshold(patch_share_, seed) : 1.0;
}

DepthRenderer::DepthRenderer(const CameraIntrinsics& intrinsics, double wall_distance_m)
    : intrinsics_(intrinsics), wall_distance_m_(wall_distance_m) {}

void DepthRenderer::AddMesh(const TriangleMesh& mesh_G, SurfaceLabel label) {
  if (mesh_G.empty()) return;
  const unsigned id = raycaster_.AddMesh(mesh_G);
  if (labels_.size() <= id) labels_.resize(id + 1, SurfaceLabel::kNone);
  labels_[id] = label;
  bounds_G_.extend(mesh::Bounds(mesh_G));
}

void DepthRenderer::Commit() { raycaster_.Commit(); }

void DepthRenderer::Render(const Eigen::Isometry3d& T_C_G, IdealDepthImage* out) const {
  const int width = intrinsics_.width;
  const int height = intrinsics_.height;
  const size_t n = static_cast<size_t>(width) * height;
  out->intrinsics = intrinsics_;
  out->depth_m.assign(n, 0.0f);
  out->cos_incidence.assign(n, 0.0f);
  out->label.assign(n, SurfaceLabel::kNone);
  const bool marks = projector_shadow_ || patch_share_ > 0.0;
  out->unlit.assign(marks ? n : 0, kLit);
  const double fx = intrinsics_.fx;
  const double fy = intrinsics_.fy;
  const double cx = intrinsics_.cx;
  const double cy = intrinsics_.cy;

  // The wall: ray (x, y, 1) meets z = D at depth D, incidence cos = 1/|ray|.
  if (wall_distance_m_ > 0.0) {
    for (int v = 0; v < height; ++v) {
      const double y = (v - cy) / fy;
      for (int u = 0; u < width; ++u) {
        const double x = (u - cx) / fx;
        const size_t i = static_cast<size_t>(v) * width + u;
        out->depth_m[i] = static_cast<float>(wall_distance_m_);
        out->cos_incidence[i] = static_cast<float>(1.0 / std::sqrt(x * x + y * y + 1.0));
        out->label[i] = SurfaceLabel::kBackground;
      }
    }
  }
  if (bounds_G_.isEmpty()) return;

  // Region of interest: the projection of the meshes' bounding box.
  int u0 = 0, u1 = width - 1, v0 = 0, v1 = height - 1;
  bool all_in_front = true;
  double umin = std::numeric_limits<double>::infinity(), umax = -umin;
  double vmin = umin, vmax = -umin;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d p_C = T_C_G * bounds_G_.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k));
    if (p_C.z() < kMinProjectionDepthM) {
      all_in_front = false;
      break;
    }
    const double u = fx * p_C.x() / p_C.z() + cx;
    const double v = fy * p_C.y() / p_C.z() + cy;
    umin = std::min(umin, u);
    umax = std::max(umax, u);
    vmin = std::min(vmin, v);
    vmax = std::max(vmax, v);
  }
  if (all_in_front) {
    if (umax < 0.0 || vmax < 0.0 || umin > width - 1 || vmin > height - 1) return;
    u0 = std::max(0, static_cast<int>(std::floor(umin)) - kRoiMarginPx);
    u1 = std::min(width - 1, static_cast<int>(std::ceil(umax)) + kRoiMarginPx);
    v0 = std::max(0, static_cast<int>(std::floor(vmin)) - kRoiMarginPx);
    v1 = std::min(height - 1, static_cast<int>(std::ceil(vmax)) + kRoiMarginPx);
  }

  // Cast in G: with the C direction (x, y, 1) rotated into G, the hit
  // distance t is the z-depth in C.
  const Eigen::Isometry3d T_G_C = T_C_G.inverse();
  const Eigen::Matrix3f R_G_C = T_G_C.linear().cast<float>();
  const Eigen::Vector3f origin_G = T_G_C.translation().cast<float>();
  const Eigen::Vector3f projector_G = (T_G_C * projector_C_).cast<float>();
  const float t_far =
      wall_distance_m_ > 0.0 ? static_cast<float>(wall_distance_m_) : std::numeric_limits<float>::infinity();
  for (int v = v0; v <= v1; ++v) {
    const float y = static_cast<float>((v - cy) / fy);
    for (int u = u0; u <= u1; ++u) {
      const float x = static_cast<float>((u - cx) / fx);
      const Eigen::Vector3f dir_G = R_G_C * Eigen::Vector3f(x, y, 1.0f);
      const RayHit hit = raycaster_.Cast(origin_G, dir_G, 0.0f, t_far);
      if (!hit.hit()) continue;
      const size_t i = static_cast<size_t>(v) * width + u;
      out->depth_m[i] = hit.t;
      const float denom = hit.normal.norm() * dir_G.norm();
      out->cos_incidence[i] = denom > 0.0f ? std::abs(hit.normal.dot(dir_G)) / denom : 0.0f;
      out->label[i] = hit.geom_id < labels_.size() ? labels_[hit.geom_id] : SurfaceLabel::kNone;
      if (!marks) continue;
      const Eigen::Vector3f p_G = origin_G + hit.t * dir_G;
      if (projector_shadow_) {
        const Eigen::Vector3f to_projector = projector_G - p_G;
        const float length = to_projector.norm();
        if (length > kShadowOffsetM &&
            raycaster_.Occluded(p_G, to_projector / length, kShadowOffsetM, length - kShadowOffsetM)) {
          out->unlit[i] |= kProjectorShadow;
        }
      }
      if (patch_share_ > 0.0 && out->label[i] == SurfaceLabel::kObject &&
          PatchField(p_G.cast<double>(), patch_cell_m_, patch_seed_) > patch_threshold_) {
        out->unlit[i] |= kDarkPatch;
      }
    }
  }
}

SceneRenderer::SceneRenderer(const Scene& scene)
    : scene_(scene),
      renderer_(scene.config().intrinsics, scene.config().environment.wall_distance_m),
      object_renderer_(scene.config().intrinsics, 0.0) {
  if (scene.slip().config().any()) {
    object_renderer_.AddMesh(scene.object_G(), SurfaceLabel::kObject);
    object_renderer_.Commit();
  } else {
    renderer_.AddMesh(scene.object_G(), SurfaceLabel::kObject);
  }
  renderer_.AddMesh(scene.claw_G(), SurfaceLabel::kClaw);
  renderer_.AddMesh(scene.arm_G(), SurfaceLabel::kArm);
  renderer_.Commit();
  // The patches' field is the scene's, apart from the frames' noise; a
  // slipping object shadows only itself (its own renderer).
  const uint64_t patches = DeriveSeed(scene.config().seed, 0xDA4Cull);
  renderer_.SetUnlit(scene.config().sensor, patches);
  object_renderer_.SetUnlit(scene.config().sensor, patches);
}

IdealDepthImage SceneRenderer::RenderIdeal(int frame_index) const {
  const int64_t utime = scene_.DepthUtime(frame_index);
  const Eigen::Isometry3d T_C_G = scene_.T_C_G_AtUtime(utime);
  IdealDepthImage image;
  renderer_.Render(T_C_G, &image);
  if (scene_.slip().config().any()) {
    // The object mesh is as grasped; where it has slipped to at this time
    // maps into C through T_C_G * S_G.
    IdealDepthImage object;
    object_renderer_.Render(T_C_G * scene_.ObjectSlipAt(utime), &object);
    OverlayNearer(object, &image);
  }
  return image;
}

DepthFrame SceneRenderer::Render(int frame_index) const {
  return ApplySensorModel(scene_.config().sensor, RenderIdeal(frame_index),
                          DeriveSeed(scene_.config().seed, static_cast<uint64_t>(frame_index)),
                          scene_.DepthUtime(frame_index));
}

}  // namespace graspfill::synth
