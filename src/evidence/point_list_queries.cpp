// SPDX-License-Identifier: BSD-3-Clause
#include "point_list_queries.hpp"

#include <algorithm>

namespace graspfill::evidence {
namespace {

// Towards V's axis (x = y = 0), in the input frame; +x when on the axis.
Eigen::Vector3f Inward(const Eigen::Isometry3f& T_in_V, const Eigen::Vector3f& p_V) {
  Eigen::Vector3f d(-p_V.x(), -p_V.y(), 0.0f);
  if (!(d.norm() > 1e-6f)) d = Eigen::Vector3f::UnitX();
  return T_in_V.linear() * d;
}

}  // namespace

double SeenFreeShare(const VisibilityRecord& record, const std::vector<Eigen::Vector3f>& points_V,
                     const Eigen::Isometry3f& T_in_V, const std::vector<char>* uncounted) {
  size_t counted = 0, free = 0;
  size_t first_key_frame = 0;  // neighbouring points are mostly carved by the same key frame
  for (size_t i = 0; i < points_V.size(); ++i) {
    if (uncounted != nullptr && (*uncounted)[i]) continue;
    ++counted;
    free += record.SeenFree(T_in_V * points_V[i], 0.0f, false, &first_key_frame);
  }
  return counted > 0 ? static_cast<double>(free) / static_cast<double>(counted) : 0.0;
}

std::vector<char> SeenFreeFlags(const VisibilityRecord& record, const std::vector<Eigen::Vector3f>& points_V,
                                const Eigen::Isometry3f& T_in_V) {
  std::vector<char> free(points_V.size(), 0);
  size_t first_key_frame = 0;  // neighbouring points are mostly carved by the same key frame
  for (size_t i = 0; i < points_V.size(); ++i) {
    free[i] = record.SeenFree(T_in_V * points_V[i], 0.0f, false, &first_key_frame);
  }
  return free;
}

int DropSeenFree(const VisibilityRecord& record, const Eigen::Isometry3f& T_in_V,
                 std::vector<Eigen::Vector3f>* points_V, float above_z_V) {
  const size_t before = points_V->size();
  size_t first_key_frame = 0;  // neighbouring points are mostly carved by the same key frame
  points_V->erase(std::remove_if(points_V->begin(), points_V->end(),
                                 [&](const Eigen::Vector3f& p) {
                                   return p.z() > above_z_V &&
                                          record.SeenFree(T_in_V * p, 0.0f, false, &first_key_frame);
                                 }),
                  points_V->end());
  return static_cast<int>(before - points_V->size());
}

int PushOutOfClaw(const VisibilityRecord& record, const Eigen::Isometry3f& T_in_V,
                  std::vector<Eigen::Vector3f>* points_V) {
  if (!record.has_claw()) return 0;
  const Eigen::Isometry3f T_V_in = T_in_V.inverse();
  int moved = 0;
  for (Eigen::Vector3f& p : *points_V) {
    if (const auto exit = record.ExitClaw(T_in_V * p, Inward(T_in_V, p))) {
      p = T_V_in * *exit;
      ++moved;
    }
  }
  return moved;
}

int DropInsideClaw(const VisibilityRecord& record, const Eigen::Isometry3f& T_in_V,
                   std::vector<Eigen::Vector3f>* points_V, float above_z_V) {
  if (!record.has_claw()) return 0;
  const size_t before = points_V->size();
  points_V->erase(std::remove_if(points_V->begin(), points_V->end(),
                                 [&](const Eigen::Vector3f& p) {
                                   return p.z() > above_z_V &&
                                          record.ExitClaw(T_in_V * p, Inward(T_in_V, p)).has_value();
                                 }),
                  points_V->end());
  return static_cast<int>(before - points_V->size());
}

double ObservedSeenFreeShare(const VisibilityRecord& record, const ObjectCloud& cloud_G, size_t max_tested) {
  const size_t n = cloud_G.points_G.size();
  const size_t stride = max_tested > 0 ? std::max<size_t>(1, n / max_tested) : 1;
  size_t tested = 0, free = 0;
  for (size_t i = 0; i < n; i += stride) {
    if (!cloud_G.provenance.empty() && cloud_G.provenance[i] != Provenance::kObserved) continue;
    ++tested;
    free += record.SeenFree(cloud_G.points_G[i]);
  }
  return tested ? static_cast<double>(free) / tested : 0.0;
}

}  // namespace graspfill::evidence
