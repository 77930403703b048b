// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/evidence/safe_bound.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace graspfill::evidence {

void SafeBoundConfig::Validate() const {
  if (!(voxel_m >= 0.0005 && voxel_m <= 0.1)) {
    throw std::invalid_argument("SafeBoundConfig: voxel_m must be in [0.0005, 0.1] m");
  }
}

SafeBound WholeBox(const fusion::WorkspaceBox& box, const SafeBoundConfig& config) {
  config.Validate();
  SafeBound bound;
  bound.origin_G = box.min_G.cast<float>();
  bound.voxel_m = static_cast<float>(config.voxel_m);
  const Eigen::Vector3d extent = box.max_G - box.min_G;
  bound.nx = std::max(1, static_cast<int>(std::ceil(extent.x() / config.voxel_m)));
  bound.ny = std::max(1, static_cast<int>(std::ceil(extent.y() / config.voxel_m)));
  bound.nz = std::max(1, static_cast<int>(std::ceil(extent.z() / config.voxel_m)));
  const size_t n = static_cast<size_t>(bound.nx) * bound.ny * bound.nz;
  bound.bits.assign((n + 7) / 8, 0xff);
  if (n % 8 != 0) bound.bits.back() = static_cast<uint8_t>((1u << (n % 8)) - 1u);
  return bound;
}

void CarveSafeBound(const VisibilityRecord& record, size_t first_key_frame, SafeBound* bound) {
  // A voxel is carved only when all of it is free: its centre by the
  // margin plus half its diagonal. Each key frame is asked about the
  // voxels still standing, up to a chunk of a row at a time.
  const float half_diagonal = 0.5f * std::sqrt(3.0f) * bound->voxel_m;
  constexpr int kChunk = 64;
  float x_G[kChunk];
  size_t voxel[kChunk];
  uint8_t seen_free[kChunk];
  for (size_t frame = first_key_frame; frame < record.size(); ++frame) {
    size_t b = 0;
    for (int k = 0; k < bound->nz; ++k) {
      for (int j = 0; j < bound->ny; ++j) {
        // The centres as Eigen sums them: origin + voxel * (index + 0.5).
        const float y_G = bound->origin_G.y() + bound->voxel_m * (static_cast<float>(j) + 0.5f);
        const float z_G = bound->origin_G.z() + bound->voxel_m * (static_cast<float>(k) + 0.5f);
        int standing = 0;
        const auto carve = [&] {
          record.SeenFreeAlongX(frame, x_G, standing, y_G, z_G, half_diagonal, /*coarse=*/true, seen_free);
          for (int s = 0; s < standing; ++s) {
            if (seen_free[s]) bound->bits[voxel[s] >> 3] &= uint8_t(~(1u << (voxel[s] & 7)));
          }
          standing = 0;
        };
        for (int i = 0; i < bound->nx; ++i, ++b) {
          if (!(bound->bits[b >> 3] & uint8_t(1u << (b & 7)))) continue;
          x_G[standing] = bound->origin_G.x() + bound->voxel_m * (static_cast<float>(i) + 0.5f);
          voxel[standing++] = b;
          if (standing == kChunk) carve();
        }
        if (standing > 0) carve();
      }
    }
  }
}

SafeBound ComputeSafeBound(const VisibilityRecord& record, const SafeBoundConfig& config) {
  config.Validate();
  if (const auto& kept = record.safe_bound(); kept && kept->voxel_m == static_cast<float>(config.voxel_m)) {
    return *kept;
  }
  SafeBound bound = WholeBox(record.workspace(), config);
  CarveSafeBound(record, 0, &bound);
  return bound;
}

}  // namespace graspfill::evidence
