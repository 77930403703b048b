// SPDX-License-Identifier: BSD-3-Clause
// ClawMask: the claw's per-pixel depth from the camera (z-buffer
// rasterization of the posed triangles, or Embree rays), restricted to where
// the claw projects, then the depth test and a separable square dilation.
#include "graspfill/claw/claw_mask.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "graspfill/core/raycaster.hpp"

namespace graspfill::claw {
namespace {

// Inclusive pixel rectangle; empty when u1 < u0 or v1 < v0.
struct Rect {
  int u0{0}, v0{0}, u1{-1}, v1{-1};
  bool empty() const { return u1 < u0 || v1 < v0; }
  void Extend(int u_lo, int v_lo, int u_hi, int v_hi) {
    if (empty()) {
      *this = Rect{u_lo, v_lo, u_hi, v_hi};
      return;
    }
    u0 = std::min(u0, u_lo);
    v0 = std::min(v0, v_lo);
    u1 = std::max(u1, u_hi);
    v1 = std::max(v1, v_hi);
  }
};

Rect Grow(const Rect& r, int px, int width, int height) {
  if (r.empty()) return r;
  return {std::max(0, r.u0 - px), std::max(0, r.v0 - px), std::min(width - 1, r.u1 + px),
          std::min(height - 1, r.v1 + px)};
}

// Side of the square pixel tiles cast as one 16-ray packet: square tiles
// keep a packet's rays coherent (they traverse the same BVH nodes).
constexpr int kTile = 4;
// Points nearer to the camera plane than this do not project reliably;
// frames with claw vertices there fall back to rays over the box rectangle.
constexpr float kMinDepthM = 1e-3f;
// Barycentric slack so that a pixel centre exactly on an edge shared by two
// triangles is inside at least one of them despite rounding (Embree's
// watertight test hits there too).
constexpr double kEdgeSlack = 1e-7;

// floor/ceil to int without libm calls (baseline x86-64 has no rounding
// instruction, and these run once per triangle row). |x| < 2^31 assumed.
inline int FloorToInt(double x) {
  const int i = static_cast<int>(x);
  return i > x ? i - 1 : i;
}
inline int CeilToInt(double x) {
  const int i = static_cast<int>(x);
  return i < x ? i + 1 : i;
}

// Where a triangle's pixel centres lie on each row: each barycentric weight
// w = k_u du + k_v dv + k_0 >= -slack bounds du = u - a.u from below
// (k_u > 0) or above (k_u < 0) by an affine function of dv = v - a.v, so
// that long thin triangles (common in STL meshes) cost their covered
// pixels, not their box. Bounds (b_0, b_v) on du = b_0 + b_v dv; the three
// k_u sum to 0, so at most two bounds of each kind.
struct RowSpans {
  double lower[2][2];
  double upper[2][2];
};

RowSpans RowSpansOf(const double (&k)[3][3]) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  RowSpans spans = {{{-kInf, 0.0}, {-kInf, 0.0}}, {{kInf, 0.0}, {kInf, 0.0}}};
  int num_lower = 0;
  int num_upper = 0;
  for (const auto& e : k) {
    if (e[0] == 0.0) continue;  // parallel to rows: left to the pixel test
    double* bound = nullptr;
    if (e[0] > 0.0 && num_lower < 2) bound = spans.lower[num_lower++];
    if (e[0] < 0.0 && num_upper < 2) bound = spans.upper[num_upper++];
    if (bound == nullptr) continue;
    bound[0] = (-kEdgeSlack - e[2]) / e[0];
    bound[1] = -e[1] / e[0];
  }
  return spans;
}

// Draws the triangle a, b, c (pixels u, v and 1/z) into the 1/z buffer
// `inverse_depth` (rows of `width`), the nearest (largest 1/z) winning,
// within box_roi; *drawn grows by the pixel box it may have covered.
void DrawInverseDepth(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                      const Rect& box_roi, int width, float* inverse_depth, Rect* drawn) {
  const double area2 = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
  if (area2 == 0.0) return;  // seen edge-on: no ray hits its inside
  // Pixel centres inside the triangle's box, within the box rectangle
  // (which is clipped to the image: no overflow below).
  const double u_min = std::max<double>(box_roi.u0, std::min({a.x(), b.x(), c.x()}));
  const double u_max = std::min<double>(box_roi.u1, std::max({a.x(), b.x(), c.x()}));
  const double v_min = std::max<double>(box_roi.v0, std::min({a.y(), b.y(), c.y()}));
  const double v_max = std::min<double>(box_roi.v1, std::max({a.y(), b.y(), c.y()}));
  if (u_max < u_min || v_max < v_min) return;
  const int u0 = CeilToInt(u_min);
  const int u1 = FloorToInt(u_max);
  const int v0 = CeilToInt(v_min);
  const int v1 = FloorToInt(v_max);
  if (u1 < u0 || v1 < v0) return;
  drawn->Extend(u0, v0, u1, v1);
  // Barycentric weights of b and c as affine functions of
  // (du, dv) = (u - a.u, v - a.v); w_a = 1 - w_b - w_c.
  const double inv_area2 = 1.0 / area2;
  const double wb_u = (c.y() - a.y()) * inv_area2;
  const double wb_v = -(c.x() - a.x()) * inv_area2;
  const double wc_u = -(b.y() - a.y()) * inv_area2;
  const double wc_v = (b.x() - a.x()) * inv_area2;
  const double iz_b = b.z() - a.z();
  const double iz_c = c.z() - a.z();
  const double k[3][3] = {{wb_u, wb_v, 0.0}, {wc_u, wc_v, 0.0}, {-(wb_u + wc_u), -(wb_v + wc_v), 1.0}};
  const RowSpans spans = RowSpansOf(k);
  for (int v = v0; v <= v1; ++v) {
    const double dv = v - a.y();
    const double du_lo = std::max({spans.lower[0][0] + spans.lower[0][1] * dv,
                                   spans.lower[1][0] + spans.lower[1][1] * dv, u_min - a.x()});
    const double du_hi = std::min({spans.upper[0][0] + spans.upper[0][1] * dv,
                                   spans.upper[1][0] + spans.upper[1][1] * dv, u_max - a.x()});
    if (du_hi < du_lo) continue;
    // Rounding of the bounds is covered by re-testing each pixel.
    const int u_lo = std::max(u0, CeilToInt(a.x() + du_lo - 1e-6));
    const int u_hi = std::min(u1, FloorToInt(a.x() + du_hi + 1e-6));
    float* depth_row = &inverse_depth[static_cast<size_t>(v) * width];
    for (int u = u_lo; u <= u_hi; ++u) {
      const double du = u - a.x();
      const double wb = wb_u * du + wb_v * dv;
      const double wc = wc_u * du + wc_v * dv;
      if (wb < -kEdgeSlack || wc < -kEdgeSlack || wb + wc > 1.0 + kEdgeSlack) continue;
      // Nearest = largest 1/z; the empty value 0 loses to any triangle.
      const float inv_z = static_cast<float>(a.z() + wb * iz_b + wc * iz_c);
      float& d = depth_row[u];
      d = std::max(d, inv_z);
    }
  }
}

}  // namespace

struct ClawMask::Impl {
  ClawMaskConfig config;
  Raycaster raycaster;
  bool has_claw{false};
  Eigen::AlignedBox3f box_G;  // claw's bounding box in G
  std::vector<Eigen::Vector3f> vertices_G;
  std::vector<Eigen::Vector3i> triangles;
  std::vector<Eigen::Vector3f> vertices_px;  // per frame: u, v [px], 1/z [1/m]

  // Buffers sized to the last frame; reused to avoid per-frame allocation.
  int width{0};
  int height{0};
  std::vector<float> claw_depth_m;  // whole image, 0 = no claw
  std::vector<uint8_t> removed;     // before dilation, valid in work rect
  std::vector<uint8_t> dilated_u;   // after the horizontal pass
  std::vector<int> column_count;    // vertical pass: window sums per column
  // kTile x kTile pixel tiles that a claw triangle may cover; rays are cast
  // only there. Valid inside the tile range of the frame's box rectangle.
  int tiles_w{0};
  int tiles_h{0};
  std::vector<uint8_t> tiles;
  Rect last_drawn;  // where claw_depth_m may be non-zero
  int ray_count{0};

  void Resize(int w, int h) {
    width = w;
    height = h;
    const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
    claw_depth_m.assign(n, 0.0f);
    removed.assign(n, 0);
    dilated_u.assign(n, 0);
    column_count.assign(static_cast<size_t>(w), 0);
    tiles_w = (w + kTile - 1) / kTile;
    tiles_h = (h + kTile - 1) / kTile;
    tiles.assign(static_cast<size_t>(tiles_w) * tiles_h, 0);
    last_drawn = Rect{};
  }

  Rect ProjectClawBox(const Eigen::Isometry3d& T_C_G, const CameraIntrinsics& K, bool* any_visible) const;
  bool ProjectVertices(const Eigen::Isometry3d& T_C_G, const CameraIntrinsics& K);
  Rect Rasterize(const Rect& box_roi);
  Rect MarkTiles(const Rect& box_roi, bool vertices_projected);
  void CastSingle(const Rect& roi, const Eigen::Vector3f& origin_G, const Eigen::Matrix3f& R_G_C,
                  const CameraIntrinsics& K);
  void CastPackets(const Rect& roi, const Eigen::Vector3f& origin_G, const Eigen::Matrix3f& R_G_C,
                   const CameraIntrinsics& K);
  int RemoveAndDilate(const Rect& drawn, float* depth);
};

ClawMask::ClawMask(const ClawMaskConfig& config) : impl_(std::make_unique<Impl>()) {
  if (!(config.front_margin_m >= 0.0) || config.dilation_px < 0 || config.roi_margin_px < 0) {
    throw std::invalid_argument(
        "ClawMaskConfig: front_margin_m, dilation_px and roi_margin_px must "
        "be >= 0");
  }
  impl_->config = config;
}

ClawMask::~ClawMask() = default;

void ClawMask::SetClaw(const TriangleMesh& claw_G) {
  Impl& m = *impl_;
  m.raycaster.Clear();
  m.has_claw = false;
  m.box_G.setEmpty();
  m.vertices_G.clear();
  m.triangles.clear();
  // Embree is always built: ray methods use it, and so does the
  // rasterizer's fallback for claws touching the camera plane.
  if (!claw_G.empty()) {
    m.raycaster.AddMesh(claw_G);  // checks the indices first
    m.vertices_G = claw_G.vertices;
    m.triangles = claw_G.triangles;
    m.vertices_px.resize(claw_G.vertices.size());
    // Only vertices used by a triangle can be hit.
    for (const Eigen::Vector3i& t : claw_G.triangles) {
      for (int k = 0; k < 3; ++k) m.box_G.extend(claw_G.vertices[t[k]]);
    }
    m.has_claw = true;
  }
  m.raycaster.Commit();
}

Rect ClawMask::Impl::ProjectClawBox(const Eigen::Isometry3d& T_C_G, const CameraIntrinsics& K,
                                    bool* any_visible) const {
  double u_min = std::numeric_limits<double>::infinity();
  double v_min = u_min;
  double u_max = -u_min;
  double v_max = -u_min;
  bool behind = false;
  bool in_front = false;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d corner_G =
        box_G.corner(static_cast<Eigen::AlignedBox3f::CornerType>(i)).cast<double>();
    const Eigen::Vector3d p_C = T_C_G * corner_G;
    if (p_C.z() < kMinDepthM) {
      behind = true;
      continue;
    }
    in_front = true;
    const double u = K.fx * p_C.x() / p_C.z() + K.cx;
    const double v = K.fy * p_C.y() / p_C.z() + K.cy;
    u_min = std::min(u_min, u);
    u_max = std::max(u_max, u);
    v_min = std::min(v_min, v);
    v_max = std::max(v_max, v);
  }
  // Every ray looks along +z in C, so a box wholly behind the camera
  // cannot be hit.
  *any_visible = in_front;
  if (!in_front) return Rect{};
  if (behind) return Rect{0, 0, K.width - 1, K.height - 1};
  const double m = config.roi_margin_px;
  // Clamp in double before converting: far-off projections overflow int.
  const auto clamp_to = [](double x, int size) {
    return static_cast<int>(std::clamp(x, -1.0, static_cast<double>(size)));
  };
  Rect r{clamp_to(std::floor(u_min - m), K.width), clamp_to(std::floor(v_min - m), K.height),
         clamp_to(std::ceil(u_max + m), K.width), clamp_to(std::ceil(v_max + m), K.height)};
  r.u0 = std::max(r.u0, 0);
  r.v0 = std::max(r.v0, 0);
  r.u1 = std::min(r.u1, K.width - 1);
  r.v1 = std::min(r.v1, K.height - 1);
  return r;
}

bool ClawMask::Impl::ProjectVertices(const Eigen::Isometry3d& T_C_G, const CameraIntrinsics& K) {
  const Eigen::Isometry3f T = T_C_G.cast<float>();
  const float fx = static_cast<float>(K.fx);
  const float fy = static_cast<float>(K.fy);
  const float cx = static_cast<float>(K.cx);
  const float cy = static_cast<float>(K.cy);
  for (size_t i = 0; i < vertices_G.size(); ++i) {
    const Eigen::Vector3f p_C = T * vertices_G[i];
    if (p_C.z() < kMinDepthM) return false;
    const float inv_z = 1.0f / p_C.z();
    vertices_px[i] = Eigen::Vector3f(fx * p_C.x() * inv_z + cx, fy * p_C.y() * inv_z + cy, inv_z);
  }
  return true;
}

Rect ClawMask::Impl::Rasterize(const Rect& box_roi) {
  // The nearest triangle at each pixel centre is the first hit of that
  // pixel's ray; 1/z is affine in the image for a planar triangle, so
  // interpolating it gives the exact z-depth. Every vertex is in front of
  // the camera here, so 1/z > 0 wherever a triangle covers a pixel.
  Rect drawn;
  for (const Eigen::Vector3i& t : triangles) {
    DrawInverseDepth(vertices_px[t[0]].cast<double>(), vertices_px[t[1]].cast<double>(),
                     vertices_px[t[2]].cast<double>(), box_roi, width, claw_depth_m.data(), &drawn);
  }
  // The buffer held 1/z while drawing (no division per covered pixel).
  for (int v = drawn.v0; v <= drawn.v1; ++v) {
    float* row = &claw_depth_m[static_cast<size_t>(v) * width];
    for (int u = drawn.u0; u <= drawn.u1; ++u) {
      row[u] = row[u] > 0.0f ? 1.0f / row[u] : 0.0f;
    }
  }
  return drawn;
}

Rect ClawMask::Impl::MarkTiles(const Rect& box_roi, bool vertices_projected) {
  const int tx0 = box_roi.u0 / kTile;
  const int tx1 = box_roi.u1 / kTile;
  const int ty0 = box_roi.v0 / kTile;
  const int ty1 = box_roi.v1 / kTile;
  for (int ty = ty0; ty <= ty1; ++ty) {
    std::fill_n(&tiles[static_cast<size_t>(ty) * tiles_w + tx0], tx1 - tx0 + 1, uint8_t{!vertices_projected});
  }
  if (!vertices_projected) return box_roi;
  // A ray can only hit a triangle inside the triangle's projection (grown by
  // the margin): mark the tiles that projection may overlap.
  const float m = static_cast<float>(config.roi_margin_px);
  Rect used;
  for (const Eigen::Vector3i& t : triangles) {
    const Eigen::Vector2f a = vertices_px[t[0]].head<2>();
    const Eigen::Vector2f b = vertices_px[t[1]].head<2>();
    const Eigen::Vector2f c = vertices_px[t[2]].head<2>();
    const float u_lo = std::floor(std::min({a.x(), b.x(), c.x()}) - m);
    const float u_hi = std::ceil(std::max({a.x(), b.x(), c.x()}) + m);
    const float v_lo = std::floor(std::min({a.y(), b.y(), c.y()}) - m);
    const float v_hi = std::ceil(std::max({a.y(), b.y(), c.y()}) + m);
    // Clipped to the box rectangle (which holds every projection), so that
    // only tiles cleared above are marked.
    if (u_hi < static_cast<float>(box_roi.u0) || u_lo > static_cast<float>(box_roi.u1) ||
        v_hi < static_cast<float>(box_roi.v0) || v_lo > static_cast<float>(box_roi.v1)) {
      continue;
    }
    // Clamped in float before the conversion (huge or NaN projections must
    // not overflow int; fmax/fmin drop a NaN).
    const int u0 = static_cast<int>(
        std::fmin(std::fmax(u_lo, static_cast<float>(box_roi.u0)), static_cast<float>(box_roi.u1)));
    const int u1 = static_cast<int>(
        std::fmax(std::fmin(u_hi, static_cast<float>(box_roi.u1)), static_cast<float>(box_roi.u0)));
    const int v0 = static_cast<int>(
        std::fmin(std::fmax(v_lo, static_cast<float>(box_roi.v0)), static_cast<float>(box_roi.v1)));
    const int v1 = static_cast<int>(
        std::fmax(std::fmin(v_hi, static_cast<float>(box_roi.v1)), static_cast<float>(box_roi.v0)));
    // Tiles wholly outside one of the triangle's edges (grown by the margin)
    // are skipped: the box alone is loose for long oblique triangles.
    Eigen::Vector3f edge[3];  // (nx, ny, c): n.x + c >= 0 inside
    const float area2 = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    const Eigen::Vector2f* p[3] = {&a, &b, &c};
    const bool use_edges = std::abs(area2) > 1e-3f;
    for (int k = 0; k < 3 && use_edges; ++k) {
      const Eigen::Vector2f d = *p[(k + 1) % 3] - *p[k];
      const float sign = area2 > 0.0f ? 1.0f : -1.0f;
      const Eigen::Vector2f n = sign * Eigen::Vector2f(-d.y(), d.x()) / d.norm();
      edge[k] = Eigen::Vector3f(n.x(), n.y(), -n.dot(*p[k]) + m + 0.5f);
    }
    for (int ty = v0 / kTile; ty <= v1 / kTile; ++ty) {
      const float y0 = static_cast<float>(ty * kTile);
      const float y1 = y0 + (kTile - 1);
      uint8_t* tile_row = &tiles[static_cast<size_t>(ty) * tiles_w];
      for (int tx = u0 / kTile; tx <= u1 / kTile; ++tx) {
        if (tile_row[tx]) continue;
        const float x0 = static_cast<float>(tx * kTile);
        const float x1 = x0 + (kTile - 1);
        bool outside = false;
        for (int k = 0; k < 3 && use_edges && !outside; ++k) {
          // The tile corner furthest inside this edge.
          const float x = edge[k].x() > 0.0f ? x1 : x0;
          const float y = edge[k].y() > 0.0f ? y1 : y0;
          outside = edge[k].x() * x + edge[k].y() * y + edge[k].z() < 0.0f;
        }
        tile_row[tx] = !outside;
      }
    }
    used.Extend(u0 / kTile * kTile, v0 / kTile * kTile, std::min(width - 1, u1 / kTile * kTile + kTile - 1),
                std::min(height - 1, v1 / kTile * kTile + kTile - 1));
  }
  return used;
}

void ClawMask::Impl::CastSingle(const Rect& roi, const Eigen::Vector3f& origin_G,
                                const Eigen::Matrix3f& R_G_C, const CameraIntrinsics& K) {
  const float inv_fx = static_cast<float>(1.0 / K.fx);
  const float inv_fy = static_cast<float>(1.0 / K.fy);
  for (int ty = roi.v0 / kTile; ty <= roi.v1 / kTile; ++ty) {
    for (int tx = roi.u0 / kTile; tx <= roi.u1 / kTile; ++tx) {
      if (!tiles[static_cast<size_t>(ty) * tiles_w + tx]) continue;
      const int v_end = std::min(ty * kTile + kTile, height);
      const int u_end = std::min(tx * kTile + kTile, width);
      for (int v = ty * kTile; v < v_end; ++v) {
        const float y = (static_cast<float>(v) - static_cast<float>(K.cy)) * inv_fy;
        for (int u = tx * kTile; u < u_end; ++u) {
          const float x = (static_cast<float>(u) - static_cast<float>(K.cx)) * inv_fx;
          const Eigen::Vector3f dir_C(x, y, 1.0f);
          const float inv_norm = 1.0f / dir_C.norm();
          const RayHit hit = raycaster.Cast(origin_G, R_G_C * (dir_C * inv_norm));
          ++ray_count;
          // z-depth = t * (unit direction).z = t / |dir_C| (dir_C.z = 1).
          claw_depth_m[static_cast<size_t>(v) * width + u] = hit.hit() ? hit.t * inv_norm : 0.0f;
        }
      }
    }
  }
}

void ClawMask::Impl::CastPackets(const Rect& roi, const Eigen::Vector3f& origin_G,
                                 const Eigen::Matrix3f& R_G_C, const CameraIntrinsics& K) {
  static_assert(kTile * kTile == 16, "one tile is one 16-ray packet");
  const float inv_fx = static_cast<float>(1.0 / K.fx);
  const float inv_fy = static_cast<float>(1.0 / K.fy);
  alignas(64) float dirs_G[16][3];
  alignas(64) float t[16];
  float inv_norm[16];
  int index[16];
  for (int ty = roi.v0 / kTile; ty <= roi.v1 / kTile; ++ty) {
    for (int tx = roi.u0 / kTile; tx <= roi.u1 / kTile; ++tx) {
      if (!tiles[static_cast<size_t>(ty) * tiles_w + tx]) continue;
      const int v_end = std::min(ty * kTile + kTile, height);
      const int u_end = std::min(tx * kTile + kTile, width);
      int count = 0;
      for (int v = ty * kTile; v < v_end; ++v) {
        const float y = (static_cast<float>(v) - static_cast<float>(K.cy)) * inv_fy;
        for (int u = tx * kTile; u < u_end; ++u) {
          const float x = (static_cast<float>(u) - static_cast<float>(K.cx)) * inv_fx;
          const Eigen::Vector3f dir_C(x, y, 1.0f);
          inv_norm[count] = 1.0f / dir_C.norm();
          const Eigen::Vector3f dir_G = R_G_C * (dir_C * inv_norm[count]);
          dirs_G[count][0] = dir_G.x();
          dirs_G[count][1] = dir_G.y();
          dirs_G[count][2] = dir_G.z();
          index[count] = v * width + u;
          ++count;
        }
      }
      raycaster.Cast16(origin_G, dirs_G, count, t);
      ray_count += count;
      for (int i = 0; i < count; ++i) {
        claw_depth_m[index[i]] = t[i] < std::numeric_limits<float>::infinity() ? t[i] * inv_norm[i] : 0.0f;
      }
    }
  }
}

int ClawMask::Impl::RemoveAndDilate(const Rect& drawn, float* depth) {
  // Pixels on or behind the claw (or without a measurement) are removed;
  // the object in front of the claw by more than the margin is kept.
  const float margin = static_cast<float>(config.front_margin_m);
  const int d = config.dilation_px;
  const Rect work = Grow(drawn, d, width, height);
  for (int v = work.v0; v <= work.v1; ++v) {
    const size_t row = static_cast<size_t>(v) * width;
    for (int u = work.u0; u <= work.u1; ++u) {
      const float claw_z = claw_depth_m[row + u];
      const float z = depth[row + u];
      // Bitwise on bools: branch-free, so the loop vectorizes.
      removed[row + u] = static_cast<uint8_t>((claw_z > 0.0f) & (!(z > 0.0f) | (z > claw_z - margin)));
    }
  }
  int count = 0;
  const auto zero = [&](size_t i) {
    if (depth[i] != 0.0f) {
      depth[i] = 0.0f;
      ++count;
    }
  };
  if (d == 0) {
    for (int v = work.v0; v <= work.v1; ++v) {
      const size_t row = static_cast<size_t>(v) * width;
      for (int u = work.u0; u <= work.u1; ++u) {
        if (removed[row + u]) zero(row + u);
      }
    }
    return count;
  }
  // Square dilation as two running-window passes (horizontal, vertical)
  // within the work rectangle, which holds every dilated pixel.
  for (int v = work.v0; v <= work.v1; ++v) {
    const uint8_t* in = &removed[static_cast<size_t>(v) * width];
    uint8_t* out = &dilated_u[static_cast<size_t>(v) * width];
    int window = 0;  // removed pixels in [u - d, u + d]
    for (int u = work.u0; u <= std::min(work.u0 + d - 1, work.u1); ++u) {
      window += in[u];
    }
    for (int u = work.u0; u <= work.u1; ++u) {
      if (u + d <= work.u1) window += in[u + d];
      if (u - d - 1 >= work.u0) window -= in[u - d - 1];
      out[u] = window > 0;
    }
  }
  // Vertical pass row by row (cache friendly): column_count[u] holds the
  // dilated_u sum over rows [v - d, v + d] of the work rectangle.
  int* columns = column_count.data();
  std::fill(columns + work.u0, columns + work.u1 + 1, 0);
  const auto add_row = [&](int v, int sign) {
    const uint8_t* row = &dilated_u[static_cast<size_t>(v) * width];
    for (int u = work.u0; u <= work.u1; ++u) columns[u] += sign * row[u];
  };
  for (int v = work.v0; v <= std::min(work.v0 + d - 1, work.v1); ++v) {
    add_row(v, 1);
  }
  for (int v = work.v0; v <= work.v1; ++v) {
    if (v + d <= work.v1) add_row(v + d, 1);
    if (v - d - 1 >= work.v0) add_row(v - d - 1, -1);
    const size_t row = static_cast<size_t>(v) * width;
    for (int u = work.u0; u <= work.u1; ++u) {
      if (columns[u] > 0) zero(row + u);
    }
  }
  return count;
}

int ClawMask::Apply(const Eigen::Isometry3d& T_C_G, DepthFrame* frame) {
  Impl& m = *impl_;
  if (frame == nullptr) return -1;
  const CameraIntrinsics& K = frame->intrinsics;
  if (K.width <= 0 || K.height <= 0 ||
      frame->depth_m.size() != static_cast<size_t>(K.width) * static_cast<size_t>(K.height)) {
    return -1;
  }
  if (K.width != m.width || K.height != m.height) m.Resize(K.width, K.height);

  // Only the last drawn rectangle can hold claw depths: clear just that.
  const Rect& last = m.last_drawn;
  for (int v = last.v0; v <= last.v1; ++v) {
    std::fill_n(&m.claw_depth_m[static_cast<size_t>(v) * m.width + last.u0], last.u1 - last.u0 + 1, 0.0f);
  }
  m.last_drawn = Rect{};
  m.ray_count = 0;
  if (!m.has_claw) return 0;

  bool any_visible = false;
  const Rect box_roi = m.ProjectClawBox(T_C_G, K, &any_visible);
  if (!any_visible || box_roi.empty()) return 0;
  const bool projected = m.ProjectVertices(T_C_G, K);
  Rect drawn;
  if (projected && m.config.method == ClawMaskMethod::kRaster) {
    drawn = m.Rasterize(box_roi);
  } else {
    // Rays in G: the scene stays committed in G, the camera moves instead.
    drawn = m.MarkTiles(box_roi, projected);
    const Eigen::Isometry3d T_G_C = T_C_G.inverse();
    const Eigen::Vector3f origin_G = T_G_C.translation().cast<float>();
    const Eigen::Matrix3f R_G_C = T_G_C.linear().cast<float>();
    if (m.config.method == ClawMaskMethod::kRays) {
      m.CastSingle(drawn, origin_G, R_G_C, K);
    } else {
      m.CastPackets(drawn, origin_G, R_G_C, K);
    }
  }
  m.last_drawn = drawn;
  if (drawn.empty()) return 0;
  return m.RemoveAndDilate(drawn, frame->depth_m.data());
}

const std::vector<float>& ClawMask::claw_depth_m() const { return impl_->claw_depth_m; }

int ClawMask::last_ray_count() const { return impl_->ray_count; }

const ClawMaskConfig& ClawMask::config() const { return impl_->config; }

}  // namespace graspfill::claw
