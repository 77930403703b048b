// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/evidence/visibility_record.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "graspfill/core/raycaster.hpp"
#include "graspfill/evidence/safe_bound.hpp"

namespace graspfill::evidence {
namespace {

// Nearer than this to the camera plane a point is not projected [m].
constexpr float kMinZ = 0.01f;

// Projects points (x, y_G, z_G) of one row along x into key frame k. One
// point and a row of them (SeenFreeAlongX) go through the same expressions,
// so they get the same bits.
class RowProjection {
 public:
  RowProjection(const KeyFrame& k, float y_G, float z_G)
      : fx_(static_cast<float>(k.intrinsics.fx)),
        fy_(static_cast<float>(k.intrinsics.fy)),
        cx_(static_cast<float>(k.intrinsics.cx)),
        cy_(static_cast<float>(k.intrinsics.cy)),
        u0_(k.roi.u0),
        v0_(k.roi.v0),
        u0_f_(static_cast<float>(k.roi.u0)),
        u1_f_(static_cast<float>(k.roi.u1)),
        v0_f_(static_cast<float>(k.roi.v0)),
        v1_f_(static_cast<float>(k.roi.v1)) {
    const Eigen::Matrix4f& T = k.T_C_G.matrix();
    for (int r = 0; r < 3; ++r) {
      x_factor_[r] = T(r, 0);
      y_term_[r] = T(r, 1) * y_G;
      z_term_[r] = T(r, 2) * z_G;
      t_[r] = T(r, 3);
    }
  }

  // The point's pixel in the rectangle (*u_roi = -1 when outside it) and
  // its depth. No branches, so that a loop over a row vectorizes.
  void operator()(float x, int* u_roi, int* v_roi, float* z) const {
    // T_C_G * p in the order Eigen evaluates it: each column times its
    // coordinate, summed left to right, then the translation.
    const float px = ((x_factor_[0] * x + y_term_[0]) + z_term_[0]) + t_[0];
    const float py = ((x_factor_[1] * x + y_term_[1]) + z_term_[1]) + t_[1];
    const float pz = ((x_factor_[2] * x + y_term_[2]) + z_term_[2]) + t_[2];
    // Pixel centres are at integer coordinates (the renderer's and the
    // crop's convention): the pixel is floor(u + 0.5). For an integer n,
    // floor(w) >= n exactly when w >= n, and floor(w) < n when w < n; and
    // w >= 0 inside, so truncation is the floor.
    const float u = fx_ * px / pz + cx_ + 0.5f;
    const float v = fy_ * py / pz + cy_ + 0.5f;
    const bool inside = (pz > kMinZ) & (u >= u0_f_) & (u < u1_f_) & (v >= v0_f_) & (v < v1_f_);
    // Converted only where inside (a select, not a branch).
    const int u_px = static_cast<int>(inside ? u : 0.0f), v_px = static_cast<int>(inside ? v : 0.0f);
    *u_roi = inside ? u_px - u0_ : -1;
    *v_roi = v_px - v0_;
    *z = pz;
  }

 private:
  float fx_, fy_, cx_, cy_;
  int u0_, v0_;
  float u0_f_, u1_f_, v0_f_, v1_f_;  // the rectangle
  float x_factor_[3], y_term_[3], z_term_[3], t_[3];
};

// Where `p_G` falls in key frame `k`: its pixel (u, v) in the rectangle
// and its depth z; false if out of the rectangle.
inline bool ProjectPixel(const KeyFrame& k, const Eigen::Vector3f& p_G, int* u_roi, int* v_roi, float* z) {
  RowProjection(k, p_G.y(), p_G.z())(p_G.x(), u_roi, v_roi, z);
  return *u_roi >= 0;
}

// Where `p_G` falls in key frame `k`: its index in the rectangle's arrays.
inline bool Project(const KeyFrame& k, const Eigen::Vector3f& p_G, size_t* index, float* z) {
  int u = 0, v = 0;
  if (!ProjectPixel(k, p_G, &u, &v, z)) return false;
  *index = static_cast<size_t>(v) * (k.roi.u1 - k.roi.u0) + static_cast<size_t>(u);
  return true;
}

// The maximum of `in` (w x h) over each block x block square (row by row,
// the last row and column of blocks cut short), into *out.
void BlockMax(const std::vector<float>& in, int w, int h, int block, std::vector<float>* out) {
  const int bw = (w + block - 1) / block, bh = (h + block - 1) / block;
  out->assign(static_cast<size_t>(bw) * bh, 0.0f);
  for (int v = 0; v < h; ++v) {
    float* row = out->data() + static_cast<size_t>(v / block) * bw;
    const float* src = in.data() + static_cast<size_t>(v) * w;
    for (int b = 0, u0 = 0; b < bw; ++b, u0 += block) {
      const float* end = src + std::min(w, u0 + block);
      row[b] = std::max(row[b], *std::max_element(src + u0, end));
    }
  }
}

}  // namespace

// Window minimum of `in` (w x h) with radius r: along the rows first, one
// shifted pass per offset (r is a few pixels; each pass runs over whole
// rows, so the compiler vectorizes it), then the columns by van Herk /
// Gil-Werman run on whole rows at a time (contiguous, vectorized, and the
// cache is not strided through). Any 0 in the window gives 0, since valid
// depths are positive.
void VisibilityRecord::WindowMin(const std::vector<float>& in, int w, int h, int r, OfferScratch* scratch,
                                 std::vector<float>* out) {
  std::vector<float>& rows = scratch->rows;
  rows.resize(in.size());
  for (int v = 0; v < h; ++v) {
    const float* x = &in[static_cast<size_t>(v) * w];
    float* o = &rows[static_cast<size_t>(v) * w];
    std::copy_n(x, w, o);
    for (int k = 1; k <= r; ++k) {
      for (int u = 0; u + k < w; ++u) o[u] = std::min(o[u], x[u + k]);
      for (int u = k; u < w; ++u) o[u] = std::min(o[u], x[u - k]);
    }
  }
  const int win = 2 * r + 1, m = h + 2 * r;
  const size_t W = static_cast<size_t>(w);
  std::vector<float>& G = scratch->column_g;
  std::vector<float>& H = scratch->column_h;
  G.resize(static_cast<size_t>(m) * W);
  H.resize(static_cast<size_t>(m) * W);
  scratch->pad.assign(W, std::numeric_limits<float>::infinity());
  const float* pad = scratch->pad.data();
  const auto at = [&](int j) { return j < r || j >= h + r ? pad : &rows[static_cast<size_t>(j - r) * W]; };
  for (int j = 0; j < m; ++j) {
    const float* x = at(j);
    float* gj = &G[static_cast<size_t>(j) * W];
    if (j % win == 0) {
      std::copy_n(x, W, gj);
    } else {
      const float* prev = gj - W;
      for (size_t u = 0; u < W; ++u) gj[u] = std::min(prev[u], x[u]);
    }
  }
  for (int j = m - 1; j >= 0; --j) {
    const float* x = at(j);
    float* hj = &H[static_cast<size_t>(j) * W];
    if (j % win == win - 1 || j == m - 1) {
      std::copy_n(x, W, hj);
    } else {
      const float* next = hj + W;
      for (size_t u = 0; u < W; ++u) hj[u] = std::min(next[u], x[u]);
    }
  }
  out->resize(in.size());
  for (int v = 0; v < h; ++v) {
    const float* hv = &H[static_cast<size_t>(v) * W];
    const float* gv = &G[static_cast<size_t>(v + 2 * r) * W];
    float* o = &(*out)[static_cast<size_t>(v) * W];
    for (size_t u = 0; u < W; ++u) o[u] = std::min(hv[u], gv[u]);
  }
}

Visibility VisibilityVotes::Verdict() const {
  if (free > 0) return Visibility::kSeenFree;
  if (surface > 0) return Visibility::kSurface;
  if (behind_claw > 0) return Visibility::kBehindClaw;
  return Visibility::kNeverSeen;
}

void VisibilityConfig::Validate() const {
  if (max_key_frames < 1 || max_key_frames > 1000) {
    throw std::invalid_argument("VisibilityConfig: max_key_frames must be in [1, 1000]");
  }
  if (!(min_view_angle_deg >= 0.0 && min_view_angle_deg <= 180.0)) {
    throw std::invalid_argument("VisibilityConfig: min_view_angle_deg must be in [0, 180]");
  }
  if (!(free_margin_m > 0.0 && free_margin_m < 1.0)) {
    throw std::invalid_argument("VisibilityConfig: free_margin_m must be in (0, 1) m");
  }
  if (!(surface_margin_m > 0.0 && surface_margin_m < 1.0)) {
    throw std::invalid_argument("VisibilityConfig: surface_margin_m must be in (0, 1) m");
  }
  if (erode_px < 0 || erode_px > 8) {
    throw std::invalid_argument("VisibilityConfig: erode_px must be in [0, 8]");
  }
  if (coarse_erode_px < erode_px || coarse_erode_px > 32) {
    throw std::invalid_argument("VisibilityConfig: coarse_erode_px must be in [erode_px, 32]");
  }
  if (!(safe_bound_voxel_m == 0.0 || (safe_bound_voxel_m >= 0.0005 && safe_bound_voxel_m <= 0.1))) {
    throw std::invalid_argument("VisibilityConfig: safe_bound_voxel_m must be 0 or in [0.0005, 0.1] m");
  }
}

VisibilityRecord::VisibilityRecord(const VisibilityConfig& config, const fusion::WorkspaceBox& workspace)
    : config_(config), workspace_(workspace) {
  config_.Validate();
  workspace_.Validate();
  Reset();
}

void VisibilityRecord::Reset() {
  key_frames_.clear();
  claw_.reset();
  safe_bound_.reset();
  if (config_.safe_bound_voxel_m > 0.0) {
    SafeBoundConfig bound;
    bound.voxel_m = config_.safe_bound_voxel_m;
    safe_bound_ = std::make_shared<const SafeBound>(WholeBox(workspace_, bound));
  }
}

bool VisibilityRecord::Offer(const DepthFrame& raw, const std::vector<float>& claw_depth_m,
                             const Eigen::Isometry3d& T_C_G) {
  if (static_cast<int>(key_frames_.size()) >= config_.max_key_frames) return false;
  const Eigen::Vector3d centre = 0.5 * (workspace_.min_G + workspace_.max_G);
  const Eigen::Vector3d camera_G = T_C_G.inverse().translation();
  const Eigen::Vector3d dir = camera_G - centre;
  if (!(dir.norm() > 1e-6)) return false;
  const Eigen::Vector3f view = dir.normalized().cast<float>();
  const float cos_min = static_cast<float>(std::cos(config_.min_view_angle_deg * M_PI / 180.0));
  for (const auto& k : key_frames_) {
    if (k->view_dir_G.dot(view) > cos_min) return false;  // too close to a key frame
  }
  const CameraIntrinsics& K = raw.intrinsics;
  const size_t n = static_cast<size_t>(K.width) * K.height;
  if (raw.depth_m.size() != n || claw_depth_m.size() != n) return false;
  const fusion::PixelRect roi = fusion::ProjectBox(workspace_, T_C_G, K, config_.coarse_erode_px + 1);
  if (roi.empty()) return false;

  auto k = std::make_shared<KeyFrame>();
  k->utime = raw.utime;
  k->T_C_G = T_C_G.cast<float>();
  k->intrinsics = K;
  k->roi = roi;
  k->view_dir_G = view;
  const int w = roi.u1 - roi.u0, h = roi.v1 - roi.v0;
  k->depth_m.resize(static_cast<size_t>(w) * h);
  k->claw_depth_m.resize(static_cast<size_t>(w) * h);
  for (int v = 0; v < h; ++v) {
    const size_t src = static_cast<size_t>(v + roi.v0) * K.width + roi.u0;
    std::copy_n(&raw.depth_m[src], w, &k->depth_m[static_cast<size_t>(v) * w]);
    std::copy_n(&claw_depth_m[src], w, &k->claw_depth_m[static_cast<size_t>(v) * w]);
  }
  for (float& d : k->depth_m) {
    if (!std::isfinite(d) || d < 0.0f) d = 0.0f;  // unusable samples are "no return"
  }
  WindowMin(k->depth_m, w, h, config_.erode_px, &scratch_, &k->free_depth_m);
  WindowMin(k->depth_m, w, h, config_.coarse_erode_px, &scratch_, &k->coarse_free_depth_m);
  BlockMax(k->free_depth_m, w, h, KeyFrame::kFreeBlockPx, &k->free_depth_block_max_m);
  key_frames_.push_back(std::move(k));
  if (safe_bound_) {
    auto bound = std::make_shared<SafeBound>(*safe_bound_);
    CarveSafeBound(*this, key_frames_.size() - 1, bound.get());
    safe_bound_ = std::move(bound);
  }
  return true;
}

VisibilityVotes VisibilityRecord::Votes(const Eigen::Vector3f& p_G) const {
  VisibilityVotes votes;
  const float free_margin = static_cast<float>(config_.free_margin_m);
  const float surface_margin = static_cast<float>(config_.surface_margin_m);
  for (const auto& kp : key_frames_) {
    const KeyFrame& k = *kp;
    size_t i = 0;
    float z = 0.0f;
    if (!Project(k, p_G, &i, &z)) continue;
    const float d_free = k.free_depth_m[i];
    if (d_free > 0.0f && d_free > z + free_margin) {
      ++votes.free;
      continue;
    }
    const float claw = k.claw_depth_m[i];
    if (claw > 0.0f && claw < z - surface_margin) {
      ++votes.behind_claw;  // the claw stood between the camera and the point
      continue;
    }
    const float d = k.depth_m[i];
    if (d > 0.0f && std::abs(d - z) <= surface_margin) ++votes.surface;
  }
  return votes;
}

bool VisibilityRecord::SeenFree(const Eigen::Vector3f& p_G, float extra_m, bool coarse,
                                size_t* first_key_frame) const {
  const size_t n = key_frames_.size();
  const size_t first = first_key_frame && *first_key_frame < n ? *first_key_frame : 0;
  // The repair asks this for every point it proposes, mostly of space no
  // key frame saw free (all of them asked): no division in the walk.
  for (size_t k = 0, f = first; k < n; ++k, f = f + 1 == n ? 0 : f + 1) {
    if (FreeIn(*key_frames_[f], p_G, extra_m, coarse)) {
      if (first_key_frame) *first_key_frame = f;
      return true;
    }
  }
  return false;
}

bool VisibilityRecord::SeenFreeBy(size_t key_frame, const Eigen::Vector3f& p_G, float extra_m,
                                  bool coarse) const {
  return FreeIn(*key_frames_.at(key_frame), p_G, extra_m, coarse);
}

bool VisibilityRecord::FreeIn(const KeyFrame& kf, const Eigen::Vector3f& p_G, float extra_m,
                              bool coarse) const {
  int u = 0, v = 0;
  float z = 0.0f;
  if (!ProjectPixel(kf, p_G, &u, &v, &z)) return false;
  return FreeAt(kf, u, v, z, extra_m, coarse);
}

bool VisibilityRecord::FreeAt(const KeyFrame& kf, int u, int v, float z, float extra_m, bool coarse) const {
  const float beyond = z + static_cast<float>(config_.free_margin_m) + extra_m;
  const int blocks_per_row = (kf.roi.u1 - kf.roi.u0 + KeyFrame::kFreeBlockPx - 1) / KeyFrame::kFreeBlockPx;
  const size_t block = static_cast<size_t>(v / KeyFrame::kFreeBlockPx) * blocks_per_row +
                       static_cast<size_t>(u / KeyFrame::kFreeBlockPx);
  // The coarse window holds the fine one (Validate), so its minimum is at
  // most the fine one's: the fine blocks answer for both.
  if (!(kf.free_depth_block_max_m[block] > beyond)) return false;
  const size_t i = static_cast<size_t>(v) * (kf.roi.u1 - kf.roi.u0) + static_cast<size_t>(u);
  const float d_free = coarse ? kf.coarse_free_depth_m[i] : kf.free_depth_m[i];
  return d_free > 0.0f && d_free > beyond;
}

void VisibilityRecord::SeenFreeAlongX(size_t key_frame, const float* x_G, int count, float y_G, float z_G,
                                      float extra_m, bool coarse, uint8_t* seen_free) const {
  const KeyFrame& k = *key_frames_.at(key_frame);
  const RowProjection project(k, y_G, z_G);
  // A chunk of points projected at a time (a loop the compiler vectorizes:
  // two divisions a point), then read one by one.
  constexpr int kChunk = 64;  // on the stack: a key frame allocates only what it keeps
  int u_roi[kChunk], v_roi[kChunk];
  float z_C[kChunk];
  for (int start = 0; start < count; start += kChunk) {
    const int n = std::min(kChunk, count - start);
    for (int i = 0; i < n; ++i) project(x_G[start + i], &u_roi[i], &v_roi[i], &z_C[i]);
    for (int i = 0; i < n; ++i) {
      seen_free[start + i] = u_roi[i] >= 0 && FreeAt(k, u_roi[i], v_roi[i], z_C[i], extra_m, coarse);
    }
  }
}

struct VisibilityRecord::ClawSolid {
  Raycaster scene;
};

void VisibilityRecord::SetClaw(const TriangleMesh& claw_G) {
  auto solid = std::make_shared<ClawSolid>();
  solid->scene.AddMesh(claw_G);
  solid->scene.Commit();
  claw_ = std::move(solid);
}

std::optional<Eigen::Vector3f> VisibilityRecord::ExitClaw(const Eigen::Vector3f& p_G,
                                                          const Eigen::Vector3f& dir_G) const {
  if (!claw_ || !(dir_G.norm() > 0.0f)) return std::nullopt;
  const Eigen::Vector3f dir = dir_G.normalized();
  const RayHit hit = claw_->scene.Cast(p_G, dir);
  // Leaving through a face means hitting it from behind.
  if (!hit.hit() || !(hit.normal.dot(dir) > 0.0f)) return std::nullopt;
  return p_G + hit.t * dir;
}

size_t VisibilityRecord::memory_bytes() const {
  size_t bytes = 0;
  for (const auto& k : key_frames_) {
    bytes += sizeof(float) * (k->depth_m.size() + k->free_depth_m.size() + k->coarse_free_depth_m.size() +
                              k->claw_depth_m.size() + k->free_depth_block_max_m.size());
  }
  return bytes;
}

}  // namespace graspfill::evidence
