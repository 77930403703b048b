// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/evidence/seen_free_carve.hpp"

namespace graspfill::evidence {

size_t CarveSeenFree(const VisibilityRecord& record, ObjectCloud* cloud) {
  if (record.empty()) return 0;
  const size_t n = cloud->points_G.size();
  const bool has_normals = cloud->normals_G.size() == n;
  const bool has_provenance = cloud->provenance.size() == n;
  // Neighbouring points (the cloud is sorted) are mostly seen free by the
  // same key frame: ask it first.
  size_t first_key_frame = 0;
  size_t kept = 0;
  for (size_t i = 0; i < n; ++i) {
    const bool observed = !has_provenance || cloud->provenance[i] == Provenance::kObserved;
    if (observed && record.SeenFree(cloud->points_G[i], 0.0f, false, &first_key_frame)) continue;
    if (kept != i) {
      cloud->points_G[kept] = cloud->points_G[i];
      if (has_normals) cloud->normals_G[kept] = cloud->normals_G[i];
      if (has_provenance) cloud->provenance[kept] = cloud->provenance[i];
    }
    ++kept;
  }
  cloud->points_G.resize(kept);
  if (has_normals) cloud->normals_G.resize(kept);
  if (has_provenance) cloud->provenance.resize(kept);
  return n - kept;
}

}  // namespace graspfill::evidence
