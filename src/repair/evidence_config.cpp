// SPDX-License-Identifier: BSD-3-Clause
#include "evidence_config.hpp"

#include <stdexcept>
#include <string>

namespace graspfill::repair {

void EvidenceConfig::Validate() const {
  auto share = [](double v, const char* name) {
    if (!(v >= 0.0 && v <= 1.0))
      throw std::invalid_argument(std::string("EvidenceConfig: ") + name + " must be in [0, 1]");
  };
  share(max_observed_free_share, "max_observed_free_share");
  share(max_mirror_free_share, "max_mirror_free_share");
  if (!(max_outline_mismatch >= 0.0 && max_outline_mismatch <= 10.0)) {
    throw std::invalid_argument("EvidenceConfig: max_outline_mismatch must be in [0, 10]");
  }
  share(top_free_jump, "top_free_jump");
  if (!(phantom_m >= 0.0 && phantom_m < 0.05))
    throw std::invalid_argument("EvidenceConfig: phantom_m must be in [0, 0.05) m");
  if (!(top_band_m > 0.0 && top_band_m < 0.1))
    throw std::invalid_argument("EvidenceConfig: top_band_m must be in (0, 0.1) m");
  if (!(top_step_m > 0.0 && top_step_m <= top_band_m)) {
    throw std::invalid_argument("EvidenceConfig: top_step_m must be in (0, top_band_m]");
  }
  if (!(top_jump_window_m >= 0.0 && top_jump_window_m <= top_search_m)) {
    throw std::invalid_argument("EvidenceConfig: top_jump_window_m must be in [0, top_search_m] m");
  }
  if (!(top_search_m >= top_step_m && top_search_m < 0.5)) {
    throw std::invalid_argument("EvidenceConfig: top_search_m must be in [top_step_m, 0.5) m");
  }
  share(min_flat_area_ratio, "min_flat_area_ratio");
  if (!(taper_drop_m > 0.0 && taper_drop_m < 0.2))
    throw std::invalid_argument("EvidenceConfig: taper_drop_m must be in (0, 0.2) m");
  if (!(dome_support_m >= 0.0 && dome_support_m < 0.2))
    throw std::invalid_argument("EvidenceConfig: dome_support_m must be in [0, 0.2) m");
  if (!(mirror_low_m >= 0.0 && mirror_low_m < 0.1))
    throw std::invalid_argument("EvidenceConfig: mirror_low_m must be in [0, 0.1) m");
  share(max_cap_free_share, "max_cap_free_share");
  if (!(carve_onset_m >= 0.0 && carve_onset_m < 0.01))
    throw std::invalid_argument("EvidenceConfig: carve_onset_m must be in [0, 0.01) m");
  if (!(max_mirror_lift_m >= 0.0 && max_mirror_lift_m < 0.05)) {
    throw std::invalid_argument("EvidenceConfig: max_mirror_lift_m must be in [0, 0.05) m");
  }
  if (!(ring_trust_m >= 0.0 && ring_trust_m < 0.05))
    throw std::invalid_argument("EvidenceConfig: ring_trust_m must be in [0, 0.05) m");
  if (min_cap_points < 1) throw std::invalid_argument("EvidenceConfig: min_cap_points must be >= 1");
  if (!(near_observed_m >= 0.0 && near_observed_m < 0.05)) {
    throw std::invalid_argument("EvidenceConfig: near_observed_m must be in [0, 0.05) m");
  }
  if (!(max_plane_drop_m >= 0.0 && max_plane_drop_m < 0.05)) {
    throw std::invalid_argument("EvidenceConfig: max_plane_drop_m must be in [0, 0.05) m");
  }
}

}  // namespace graspfill::repair
