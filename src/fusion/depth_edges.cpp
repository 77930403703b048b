// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/fusion/depth_edges.hpp"

#include <algorithm>
#include <cmath>

#include "frame_size_check.hpp"

namespace graspfill::fusion {

namespace {

// True when the returns a and b (both > 0) straddle a depth edge: the
// jump exceeds slope * min(a, b) + noise.
inline bool Jumps(float a, float b, float slope, float noise) {
  return std::abs(a - b) > slope * std::min(a, b) + noise;
}

}  // namespace

int RejectDepthEdges(const PixelRect& roi, DepthFrame* frame, std::vector<uint8_t>* marks) {
  const int width = frame->intrinsics.width;
  const int height = frame->intrinsics.height;
  CheckFrameSize("RejectDepthEdges", *frame, frame->intrinsics, 0);
  const size_t pixels = frame->depth_m.size();
  const int u0 = std::max(roi.u0, 0), u1 = std::min(roi.u1, width);
  const int v0 = std::max(roi.v0, 0), v1 = std::min(roi.v1, height);
  if (u1 <= u0 || v1 <= v0) return 0;
  if (marks->size() < pixels) marks->resize(pixels);
  const double tan_max = std::tan(kDepthEdgeMaxIncidenceDeg * M_PI / 180.0);
  const float slope_u = static_cast<float>(tan_max / frame->intrinsics.fx);
  const float slope_v = static_cast<float>(tan_max / frame->intrinsics.fy);
  const float noise = static_cast<float>(kDepthEdgeNoiseM);
  float* depth = frame->depth_m.data();
  uint8_t* mark = marks->data();
  for (int v = v0; v < v1; ++v) {
    std::fill(mark + static_cast<size_t>(v) * width + u0, mark + static_cast<size_t>(v) * width + u1, 0);
  }
  // Each pair once: the right and the lower neighbour.
  for (int v = v0; v < v1; ++v) {
    const size_t row = static_cast<size_t>(v) * width;
    for (int u = u0; u < u1; ++u) {
      const size_t i = row + u;
      const float z = depth[i];
      if (!(z > 0.0f)) continue;
      if (u + 1 < u1) {
        const float r = depth[i + 1];
        if (r > 0.0f && Jumps(z, r, slope_u, noise)) mark[i] = mark[i + 1] = 1;
      }
      if (v + 1 < v1) {
        const float d = depth[i + width];
        if (d > 0.0f && Jumps(z, d, slope_v, noise)) mark[i] = mark[i + width] = 1;
      }
    }
  }
  int zeroed = 0;
  for (int v = v0; v < v1; ++v) {
    const size_t row = static_cast<size_t>(v) * width;
    for (int u = u0; u < u1; ++u) {
      if (mark[row + u]) {
        depth[row + u] = 0.0f;
        ++zeroed;
      }
    }
  }
  return zeroed;
}

}  // namespace graspfill::fusion
