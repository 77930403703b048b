// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/repair/incremental_repair.hpp"

#include <stdexcept>
#include <string>

#include "neighbor_index.hpp"

namespace graspfill::repair {

namespace {
// The change grid reaches this many cells beyond the base's bulk: a fused
// point farther out is new anyway (no base point near it).
constexpr float kBoxMarginCells = 4.0f;
}  // namespace

void IncrementalConfig::Validate() const {
  if (!(cell_m > 0.0f) || !(cell_m <= 0.05f)) {
    throw std::invalid_argument("IncrementalConfig.cell_m must be in (0, 0.05] m");
  }
  if (!(max_new_surface_share >= 0.0 && max_new_surface_share <= 1.0)) {
    throw std::invalid_argument("IncrementalConfig.max_new_surface_share must be in [0, 1]");
  }
  if (!(max_dropped_share >= 0.0 && max_dropped_share <= 1.0)) {
    throw std::invalid_argument("IncrementalConfig.max_dropped_share must be in [0, 1]");
  }
  if (max_new_key_frames < 0) {
    throw std::invalid_argument("IncrementalConfig.max_new_key_frames must be >= 0");
  }
}

const char* RebaseReasonName(RebaseReason reason) {
  switch (reason) {
    case RebaseReason::kNone:
      return "none";
    case RebaseReason::kNoBase:
      return "no base";
    case RebaseReason::kOtherGrasp:
      return "other grasp";
    case RebaseReason::kNewSurface:
      return "new surface";
    case RebaseReason::kAddedDropped:
      return "added points dropped";
    case RebaseReason::kNewEvidence:
      return "new key frames";
  }
  return "none";
}

IncrementalRepair::IncrementalRepair(const IncrementalConfig& config) : config_(config) {
  config_.Validate();
}

void IncrementalRepair::Rebase(const ObjectCloud& repaired, const evidence::VisibilityRecord* record) {
  has_base_ = false;
  const bool has_normals = repaired.normals_G.size() == repaired.size();
  const bool has_confidence = repaired.confidence.size() == repaired.size();
  added_.points_G.clear();
  added_.normals_G.clear();
  added_.provenance.clear();
  added_.confidence.clear();
  PointList observed;
  observed.reserve(repaired.size());
  for (size_t i = 0; i < repaired.size(); ++i) {
    const bool is_observed =
        i >= repaired.provenance.size() || repaired.provenance[i] == Provenance::kObserved;
    if (is_observed) {
      observed.push_back(repaired.points_G[i]);
      continue;
    }
    added_.points_G.push_back(repaired.points_G[i]);
    if (has_normals) added_.normals_G.push_back(repaired.normals_G[i]);
    added_.provenance.push_back(repaired.provenance[i]);
    added_.confidence.push_back(has_confidence ? repaired.confidence[i] : 1.0f);
  }
  if (observed.empty()) {
    throw std::invalid_argument("IncrementalRepair::Rebase: the repaired cloud has no observed points");
  }
  // The bulk's box: a few stray points must not blow the grid up.
  box_ = RobustBox(observed);
  if (!added_.points_G.empty()) box_.extend(RobustBox(added_.points_G));
  const Eigen::Vector3f margin = Eigen::Vector3f::Constant(kBoxMarginCells * config_.cell_m);
  box_ = Eigen::AlignedBox3f(box_.min() - margin, box_.max() + margin);
  base_observed_.Reset(box_, config_.cell_m);  // throws for a box too large
  for (const Eigen::Vector3f& p : observed) base_observed_.Set(p, /*dilate=*/true);
  holes_ = repaired.holes;
  safe_bound_ = repaired.safe_bound;
  base_grasp_id_ = repaired.grasp_id;
  base_key_frames_ = record != nullptr ? record->size() : 0;
  has_base_ = true;
}

UpdateReport IncrementalRepair::Update(const ObjectCloud& fused, const evidence::VisibilityRecord* record,
                                       ObjectCloud* out) {
  UpdateReport report;
  if (!has_base_ || fused.grasp_id != base_grasp_id_) {
    report.rebase = has_base_ ? RebaseReason::kOtherGrasp : RebaseReason::kNoBase;
    *out = fused;
    return report;
  }

  // Which fused points are new since the base, and where they are.
  fresh_.Reset(box_, config_.cell_m);
  size_t new_points = 0;
  for (const Eigen::Vector3f& p : fused.points_G) {
    if (base_observed_.Test(p)) continue;
    ++new_points;
    fresh_.Set(p, /*dilate=*/true);
  }
  report.new_surface_share =
      fused.size() > 0 ? static_cast<double>(new_points) / static_cast<double>(fused.size()) : 0.0;

  // The base's added points that still hold.
  const bool use_record = record != nullptr && !record->empty();
  size_t first_key_frame = 0;  // neighbouring points are carved by the same key frame
  keep_.assign(added_.size(), 0);
  for (size_t i = 0; i < added_.size(); ++i) {
    const Eigen::Vector3f& p = added_.points_G[i];
    if (fresh_.Test(p)) {
      ++report.dropped_measured;
    } else if (use_record && record->SeenFree(p, 0.0f, false, &first_key_frame)) {
      ++report.dropped_free;
    } else {
      keep_[i] = 1;
      ++report.added_kept;
    }
  }

  // The model: the fused points as they are now, then the kept ones.
  out->utime = fused.utime;
  out->seq = fused.seq;
  out->frame_name = fused.frame_name;
  out->T_C_G = fused.T_C_G;
  out->grasp_id = fused.grasp_id;
  out->is_final = fused.is_final;
  out->timings = fused.timings;
  out->holes = holes_;
  out->safe_bound = safe_bound_;
  out->points_G.assign(fused.points_G.begin(), fused.points_G.end());
  const bool normals = fused.normals_G.size() == fused.size() && added_.normals_G.size() == added_.size();
  if (normals)
    out->normals_G.assign(fused.normals_G.begin(), fused.normals_G.end());
  else
    out->normals_G.clear();
  out->provenance.assign(fused.size(), Provenance::kObserved);
  out->confidence.assign(fused.size(), 1.0f);
  for (size_t i = 0; i < added_.size(); ++i) {
    if (!keep_[i]) continue;
    out->points_G.push_back(added_.points_G[i]);
    if (normals) out->normals_G.push_back(added_.normals_G[i]);
    out->provenance.push_back(added_.provenance[i]);
    out->confidence.push_back(added_.confidence[i]);
  }

  const int dropped = report.dropped_measured + report.dropped_free;
  if (report.new_surface_share > config_.max_new_surface_share) {
    report.rebase = RebaseReason::kNewSurface;
  } else if (!added_.points_G.empty() &&
             static_cast<double>(dropped) / static_cast<double>(added_.size()) > config_.max_dropped_share) {
    report.rebase = RebaseReason::kAddedDropped;
  } else if (config_.max_new_key_frames > 0 && use_record &&
             record->size() >= base_key_frames_ + static_cast<size_t>(config_.max_new_key_frames)) {
    report.rebase = RebaseReason::kNewEvidence;
  }
  return report;
}

}  // namespace graspfill::repair
