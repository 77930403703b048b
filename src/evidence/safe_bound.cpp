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
  // margin plus half its diagonal.
  const float half_diagonal = 0.5f * std::sqrt(3.0f) * bound->voxel_m;
  const size_t frames = record.size();
  if (first_key_frame >= frames) return;
  size_t b = 0;
  size_t carver = first_key_frame;  // the key frame that carved the voxel before
  for (int k = 0; k < bound->nz; ++k) {
    for (int j = 0; j < bound->ny; ++j) {
      for (int i = 0; i < bound->nx; ++i, ++b) {
        const uint8_t bit = uint8_t(1u << (b & 7));
        if (!(bound->bits[b >> 3] & bit)) continue;
        const Eigen::Vector3f centre =
            bound->origin_G + bound->voxel_m * Eigen::Vector3f(i + 0.5f, j + 0.5f, k + 0.5f);
        // Neighbouring voxels are mostly carved by the same key frame: ask
        // it first.
        for (size_t f = 0; f < frames - first_key_frame; ++f) {
          const size_t frame = first_key_frame + (carver - first_key_frame + f) % (frames - first_key_frame);
          if (record.SeenFreeBy(frame, centre, half_diagonal, /*coarse=*/true)) {
            bound->bits[b >> 3] &= uint8_t(~bit);
            carver = frame;
            break;
          }
        }
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
