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

SafeBound ComputeSafeBound(const VisibilityRecord& record, const SafeBoundConfig& config) {
  config.Validate();
  const fusion::WorkspaceBox& box = record.workspace();
  SafeBound bound;
  bound.origin_G = box.min_G.cast<float>();
  bound.voxel_m = static_cast<float>(config.voxel_m);
  const Eigen::Vector3d extent = box.max_G - box.min_G;
  bound.nx = std::max(1, static_cast<int>(std::ceil(extent.x() / config.voxel_m)));
  bound.ny = std::max(1, static_cast<int>(std::ceil(extent.y() / config.voxel_m)));
  bound.nz = std::max(1, static_cast<int>(std::ceil(extent.z() / config.voxel_m)));
  const size_t n = static_cast<size_t>(bound.nx) * bound.ny * bound.nz;
  bound.bits.assign((n + 7) / 8, 0);
  // A voxel is carved only when all of it is free: its centre by the
  // margin plus half its diagonal.
  const float half_diagonal = 0.5f * std::sqrt(3.0f) * bound.voxel_m;
  size_t b = 0;
  size_t carver = 0;  // the key frame that carved the voxel before
  for (int k = 0; k < bound.nz; ++k) {
    for (int j = 0; j < bound.ny; ++j) {
      for (int i = 0; i < bound.nx; ++i, ++b) {
        const Eigen::Vector3f centre =
            bound.origin_G + bound.voxel_m * Eigen::Vector3f(i + 0.5f, j + 0.5f, k + 0.5f);
        if (!record.SeenFree(centre, half_diagonal, /*coarse=*/true, &carver)) {
          bound.bits[b >> 3] |= uint8_t(1u << (b & 7));
        }
      }
    }
  }
  return bound;
}

}  // namespace graspfill::evidence
