// SPDX-License-Identifier: BSD-3-Clause
#include "mirror_evidence.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "evidence/point_list_queries.hpp"

namespace graspfill::repair {

double LowerMirrorOutOfFree(const evidence::VisibilityRecord& record, const EvidenceConfig& config,
                            const Eigen::Isometry3f& T_in_V, float floor_z_V, PointList* added_V,
                            std::vector<char>* uncounted) {
  if (uncounted != nullptr && uncounted->size() != added_V->size()) {
    throw std::invalid_argument("LowerMirrorOutOfFree: one uncounted flag per point is needed");
  }
  const int steps = static_cast<int>(std::floor(config.max_plane_drop_m / config.top_step_m + 1e-9));
  PointList lowered;
  std::vector<char> lowered_uncounted;
  lowered.reserve(added_V->size());
  for (int k = 0; k <= steps; ++k) {
    const float drop = static_cast<float>(k * config.top_step_m);
    lowered.clear();
    lowered_uncounted.clear();
    for (size_t i = 0; i < added_V->size(); ++i) {
      const Eigen::Vector3f& p = (*added_V)[i];
      const Eigen::Vector3f q(p.x(), p.y(), p.z() - 2.0f * drop);
      if (k > 0 && q.z() < floor_z_V) continue;
      lowered.push_back(q);
      lowered_uncounted.push_back(uncounted != nullptr ? (*uncounted)[i] : 0);
    }
    if (std::find(lowered_uncounted.begin(), lowered_uncounted.end(), 0) == lowered_uncounted.end()) break;
    if (evidence::SeenFreeShare(record, lowered, T_in_V, &lowered_uncounted) <=
        config.max_mirror_free_share) {
      added_V->swap(lowered);
      if (uncounted != nullptr) uncounted->swap(lowered_uncounted);
      return drop;
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

ImageTop TopOfImage(const PointList& image_V, double layer_m) {
  ImageTop top;
  if (image_V.empty()) return top;
  // The layer hangs from the height 1% of the image exceeds: a few strays
  // over the cap (the image of a fin at a bottom corner) would leave it a
  // handful of points.
  std::vector<float> z;
  z.reserve(image_V.size());
  for (const Eigen::Vector3f& p : image_V) z.push_back(p.z());
  top.highest_z_V = *std::max_element(z.begin(), z.end());
  const auto near_top = z.begin() + static_cast<long>(0.99 * static_cast<double>(z.size() - 1));
  std::nth_element(z.begin(), near_top, z.end());
  top.layer_from_z_V = *near_top - static_cast<float>(layer_m);
  std::vector<float> layer_z;
  for (const Eigen::Vector3f& p : image_V) {
    if (p.z() > top.layer_from_z_V) layer_z.push_back(p.z());
  }
  const auto middle = layer_z.begin() + static_cast<long>(layer_z.size() / 2);
  std::nth_element(layer_z.begin(), middle, layer_z.end());
  top.cap_z_V = *middle;
  top.layer_points = static_cast<int>(layer_z.size());
  return top;
}

float StretchImageTop(const ImageTop& top, float cap_z_V, const EvidenceConfig& config, PointList* image_V) {
  const float base = top.cap_z_V - static_cast<float>(2.0 * config.top_band_m);
  const float stretch = (cap_z_V - base) / (top.cap_z_V - base);
  for (Eigen::Vector3f& p : *image_V) {
    if (p.z() > base) p.z() = base + (p.z() - base) * stretch;
  }
  return base;
}

double MirrorLiftFromCarving(const evidence::VisibilityRecord& record, const EvidenceConfig& config,
                             const Eigen::Isometry3f& T_in_V, const ImageTop& top, const PointList& image_V) {
  constexpr double kNoAnswer = std::numeric_limits<double>::quiet_NaN();
  if (top.layer_points < config.min_cap_points) return kNoAnswer;
  // The top layer, evenly thinned: a few hundred points tell a share of 1%.
  constexpr int kMaxTested = 256;
  const int stride = std::max(1, top.layer_points / kMaxTested);
  PointList layer;
  int seen = 0;
  for (const Eigen::Vector3f& p : image_V) {
    if (p.z() > top.layer_from_z_V && seen++ % stride == 0) layer.push_back(p);
  }
  const int steps = static_cast<int>(std::floor(config.max_mirror_lift_m / config.top_step_m + 1e-9));
  PointList lifted;
  for (int k = 0; k <= steps; ++k) {
    const double lift = k * config.top_step_m;
    lifted = layer;
    StretchImageTop(top, top.cap_z_V + static_cast<float>(lift), config, &lifted);
    if (evidence::SeenFreeShare(record, lifted, T_in_V) > config.max_cap_free_share) {
      return std::max(0.0, (k - 1) * config.top_step_m - config.carve_onset_m);
    }
  }
  return kNoAnswer;
}

}  // namespace graspfill::repair
