// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/fusion/workspace_crop.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace graspfill::fusion {

void WorkspaceBox::Validate() const {
  if (!min_G.allFinite() || !max_G.allFinite() || !(min_G.array() < max_G.array()).all()) {
    throw std::invalid_argument("workspace box: need finite min < max on every axis");
  }
}

PixelRect ProjectBox(const WorkspaceBox& box, const Eigen::Isometry3d& T_C_G, const CameraIntrinsics& K,
                     int margin_px) {
  const PixelRect full{0, 0, K.width, K.height};
  double u_min = 1e30, u_max = -1e30, v_min = 1e30, v_max = -1e30;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p_G((corner & 1) ? box.max_G.x() : box.min_G.x(),
                              (corner & 2) ? box.max_G.y() : box.min_G.y(),
                              (corner & 4) ? box.max_G.z() : box.min_G.z());
    const Eigen::Vector3d p_C = T_C_G * p_G;
    if (p_C.z() <= 1e-3) return full;  // box straddles the image plane
    const double u = K.fx * p_C.x() / p_C.z() + K.cx;
    const double v = K.fy * p_C.y() / p_C.z() + K.cy;
    u_min = std::min(u_min, u);
    u_max = std::max(u_max, u);
    v_min = std::min(v_min, v);
    v_max = std::max(v_max, v);
  }
  // The projection of a box is contained in the hull of its projected
  // corners, so this rectangle is conservative.
  // Clamped in double before the conversion: huge or non-finite
  // projections (extreme intrinsics, a pose far away) must not overflow int.
  if (!std::isfinite(u_min) || !std::isfinite(u_max) || !std::isfinite(v_min) || !std::isfinite(v_max)) {
    return full;
  }
  auto to_pixel = [](double x, double offset, int size) {
    return static_cast<int>(std::clamp(x + offset, 0.0, static_cast<double>(size)));
  };
  PixelRect r;
  r.u0 = to_pixel(std::floor(u_min), -margin_px, K.width);
  r.v0 = to_pixel(std::floor(v_min), -margin_px, K.height);
  r.u1 = to_pixel(std::ceil(u_max), 1.0 + margin_px, K.width);
  r.v1 = to_pixel(std::ceil(v_max), 1.0 + margin_px, K.height);
  return r;
}

namespace {

void CheckSize(const DepthFrame& frame) {
  const CameraIntrinsics& K = frame.intrinsics;
  if (K.width <= 0 || K.height <= 0 || frame.depth_m.size() != static_cast<size_t>(K.width) * K.height) {
    throw std::invalid_argument("CropToWorkspace: the depth does not hold width x height pixels");
  }
}

// The crop from `in` into `out` (the same size; may be the same array).
int Crop(const WorkspaceBox& box, const Eigen::Isometry3d& T_C_G, const CameraIntrinsics& K, const float* in,
         float* out, PixelRect* roi) {
  const PixelRect r = ProjectBox(box, T_C_G, K);
  const int width = K.width;
  // Zero the rows above and below the rectangle, and the sides of its rows.
  std::memset(out, 0, sizeof(float) * static_cast<size_t>(r.v0) * width);
  std::memset(out + static_cast<size_t>(r.v1) * width, 0,
              sizeof(float) * static_cast<size_t>(K.height - r.v1) * width);
  // Test each pixel in G: p_G = R_G_C * p_C + t_G_C, with p_C = z * ray.
  const Eigen::Isometry3d T_G_C = T_C_G.inverse();
  const Eigen::Matrix3f R = T_G_C.linear().cast<float>();
  const Eigen::Vector3f t = T_G_C.translation().cast<float>();
  const Eigen::Array3f lo = box.min_G.cast<float>().array();
  const Eigen::Array3f hi = box.max_G.cast<float>().array();
  const float inv_fx = static_cast<float>(1.0 / K.fx);
  const float inv_fy = static_cast<float>(1.0 / K.fy);
  int kept = 0;
  for (int v = r.v0; v < r.v1; ++v) {
    const float* in_row = in + static_cast<size_t>(v) * width;
    float* row = out + static_cast<size_t>(v) * width;
    std::fill(row, row + r.u0, 0.0f);
    std::fill(row + r.u1, row + width, 0.0f);
    const float y = (static_cast<float>(v) - static_cast<float>(K.cy)) * inv_fy;
    for (int u = r.u0; u < r.u1; ++u) {
      const float z = in_row[u];
      if (!(z > 0.0f)) {
        row[u] = 0.0f;  // also clears NaN
        continue;
      }
      const float x = (static_cast<float>(u) - static_cast<float>(K.cx)) * inv_fx;
      const Eigen::Array3f p_G = (R * Eigen::Vector3f(x * z, y * z, z) + t).array();
      const bool inside = (p_G >= lo).all() && (p_G <= hi).all();
      kept += inside;
      row[u] = inside ? z : 0.0f;
    }
  }
  if (roi) *roi = r;
  return kept;
}

}  // namespace

int CropToWorkspace(const WorkspaceBox& box, const Eigen::Isometry3d& T_C_G, DepthFrame* frame,
                    PixelRect* roi) {
  CheckSize(*frame);
  return Crop(box, T_C_G, frame->intrinsics, frame->depth_m.data(), frame->depth_m.data(), roi);
}

int CropToWorkspace(const WorkspaceBox& box, const Eigen::Isometry3d& T_C_G, const DepthFrame& in,
                    DepthFrame* out, PixelRect* roi) {
  CheckSize(in);
  out->utime = in.utime;
  out->intrinsics = in.intrinsics;
  out->depth_m.resize(in.depth_m.size());
  return Crop(box, T_C_G, in.intrinsics, in.depth_m.data(), out->depth_m.data(), roi);
}

}  // namespace graspfill::fusion
