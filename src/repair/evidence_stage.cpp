// SPDX-License-Identifier: BSD-3-Clause
#include "evidence_stage.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "evidence/point_list_queries.hpp"
#include "mirror_evidence.hpp"

namespace graspfill::repair {
namespace {

// Observed points tested to tell whether a record matches the cloud.
constexpr size_t kRecordCheckPoints = 2000;

// Per point of `image_V`: an observed point at least as high lies within
// `radius_m` of it (beside a seen surface; a cap over the highest seen
// points is not).
std::vector<char> BesideObserved(const NeighborIndex& observed, double radius_m, const PointList& image_V) {
  std::vector<char> beside(image_V.size(), 0);
  if (!(radius_m > 0.0)) return beside;
  for (size_t i = 0; i < image_V.size(); ++i) {
    const float z = image_V[i].z();
    beside[i] =
        observed.AnyWithin(image_V[i], radius_m, [z](const Eigen::Vector3f& p) { return p.z() >= z; });
  }
  return beside;
}

// The claw fills: none in seen-free space, those inside the claw moved
// onto its face.
void CheckClawFills(const evidence::VisibilityRecord& record, const Eigen::Isometry3f& T_in_V,
                    PointList* surface_V, EvidenceReport* report) {
  report->rejected_free += evidence::DropSeenFree(record, T_in_V, surface_V);
  report->moved_out_of_claw += evidence::PushOutOfClaw(record, T_in_V, surface_V);
}

// A mirror image in seen-free space is lowered out of it, or refused when
// no drop takes it out; the rest of the image drops its points seen free
// or inside the claw.
void TestMirrorAgainstRecord(const evidence::VisibilityRecord& record, const EvidenceConfig& config,
                             const Eigen::Isometry3f& T_in_V, const NeighborIndex& index_V,
                             SymmetryResult* symmetry, EvidenceReport* report) {
  // The image apart from its points beside the observed surface
  // (EvidenceConfig::near_observed_m) answers for it.
  PointList& m = symmetry->added_V;
  std::vector<char> beside = BesideObserved(index_V, config.near_observed_m, m);
  // Each point is asked once: the share, and the drop below where the
  // image stays where it is (the lowering's first height is the image).
  const std::vector<char> free = evidence::SeenFreeFlags(record, m, T_in_V);
  size_t counted = 0, counted_free = 0;
  for (size_t i = 0; i < m.size(); ++i) {
    counted += !beside[i];
    counted_free += !beside[i] && free[i];
  }
  report->mirror_free_share =
      counted ? static_cast<double>(counted_free) / static_cast<double>(counted) : 0.0;
  const double drop = counted > 0 && report->mirror_free_share > config.max_mirror_free_share
                          ? LowerMirrorOutOfFree(record, config, T_in_V, symmetry->box_min_V.z(), &m, &beside)
                          : 0.0;
  if (drop > 0.0) {
    report->mirror_plane_drop_m = drop;
    report->mirror_free_share = evidence::SeenFreeShare(record, m, T_in_V, &beside);
    symmetry->symmetry_plane_z -= drop;
    char text[96];
    std::snprintf(text, sizeof(text), "; plane lowered %.2f mm: the mirror's top lay in seen-free space",
                  1000.0 * drop);
    symmetry->reason += text;
  }
  if (std::isnan(drop)) {
    symmetry->symmetric = false;
    symmetry->reason = "the mirror image contradicts what the camera saw: " +
                       std::to_string(static_cast<int>(100.0 * report->mirror_free_share + 0.5)) +
                       "% of its points lie in seen-free space (not symmetric: a handle, a spout?)";
    symmetry->added_V.clear();
  } else {
    if (drop == 0.0) {
      size_t kept = 0;
      for (size_t i = 0; i < m.size(); ++i) {
        if (!free[i]) m[kept++] = m[i];
      }
      report->rejected_free += static_cast<int>(m.size() - kept);
      m.resize(kept);
    } else {
      report->rejected_free += evidence::DropSeenFree(record, T_in_V, &m);
    }
    report->rejected_in_claw += evidence::DropInsideClaw(record, T_in_V, &m);
  }
}

// The height the rays carve the image's cap at: its cap raised until they
// do; NaN when the carve cannot tell. A plain float: GCC's
// -Wmaybe-uninitialized took an optional<float> for unset.
float CarvedImageTop(const evidence::VisibilityRecord& record, const EvidenceConfig& config,
                     const Eigen::Isometry3f& T_in_V, const ImageTop& image_top, const PointList& image_V) {
  float carved_top = std::numeric_limits<float>::quiet_NaN();
  const double lift = MirrorLiftFromCarving(record, config, T_in_V, image_top, image_V);
  if (!std::isnan(lift)) carved_top = image_top.cap_z_V + static_cast<float>(lift);
  return carved_top;
}

// The outcome, and a flat top's whole lid for the search's extrusion.
EvidenceTopPoints OutcomeAndExtrusion(const EvidenceTop& top) {
  EvidenceTopPoints result;
  result.outcome = top.outcome;
  if (top.outcome == TopEvidence::kHeightFound || top.outcome == TopEvidence::kNotObservable) {
    result.extrusion_V = top.added_V;  // the claw's test is the search's, where the walls pass
    result.extrusion_rejected = top.rejected_free;
    result.extrusion_rms_m = top.extrusion_rms_m;
    result.outline_vertices = top.outline_vertices;
  }
  return result;
}

// Under a mirror the dome is fitted to the seen band and the image
// together: over the seen band alone, to one side of the top, it sags
// a mm or two under a round top.
void RefitDomeWithImage(const evidence::VisibilityRecord& record, const EvidenceConfig& config,
                        const Eigen::Isometry3f& T_in_V, const NeighborIndex& index_V, double spacing_m,
                        const PointList& surface_V, const PointList& image_V, EvidenceTop* top) {
  PointList with_image = index_V.points();
  with_image.insert(with_image.end(), image_V.begin(), image_V.end());
  EvidenceTop over_both =
      CloseTopFromEvidence(NeighborIndex(with_image), surface_V, record, T_in_V, spacing_m, config);
  const bool dome = over_both.outcome == TopEvidence::kDome;
  top->added_V = dome ? std::move(over_both.added_V) : PointList{};
  top->rejected_free = dome ? over_both.rejected_free : 0;
  top->dome = dome ? std::move(over_both.dome) : std::nullopt;
}

// The rings' top stands when it is just under the carve (the hull is the
// top's outline); far under it, the hull is wider than the top, and over
// it the image would be carved.
bool RingsConfirmTheCarve(const EvidenceTop& top, float carved_top, const EvidenceConfig& config) {
  const float carve_starts = carved_top + static_cast<float>(config.carve_onset_m);
  return top.outcome == TopEvidence::kHeightFound && top.top_z_V <= carve_starts &&
         top.top_z_V >= carve_starts - static_cast<float>(config.ring_trust_m);
}

// Where the image's cap goes.
struct ImageCap {
  float z_V{0.0f};
  bool keep_evidence_top{false};  ///< the evidence's top is kept beside the image
};

ImageCap ChooseImageCap(const ImageTop& image_top, float carved_top, bool carved, bool rings_agree,
                        const EvidenceTop& top, const EvidenceConfig& config) {
  ImageCap cap{image_top.cap_z_V, false};
  if (carved) {
    // The image alone: the rings' points, at another outline, left a
    // sparse second sheet (the e2e prism's mesh 1.45 mm from its cloud).
    cap.z_V = carved_top;
  } else if (top.outcome == TopEvidence::kHeightFound &&
             image_top.cap_z_V < top.top_z_V - static_cast<float>(config.mirror_low_m)) {
    // Else the rings' top, when the image closes under it.
    cap.z_V = top.top_z_V;
    cap.keep_evidence_top = true;
  } else if (rings_agree && image_top.cap_z_V < top.top_z_V) {
    // The rays confirm the rings' top: the image rises to it, however
    // little (the true top lies over both).
    cap.z_V = top.top_z_V;
  }
  return cap;
}

// Stretches the image's top up to `cap_z_V` and tests what moved.
void RaiseImageCap(const evidence::VisibilityRecord& record, const EvidenceConfig& config,
                   const Eigen::Isometry3f& T_in_V, const ImageTop& image_top, float cap_z_V, bool carved,
                   SymmetryResult* symmetry, EvidenceReport* report) {
  PointList& m = symmetry->added_V;
  // Only the stretched points moved; the rest passed both tests above.
  const float moved_above = StretchImageTop(image_top, cap_z_V, config, &m);
  report->rejected_free += evidence::DropSeenFree(record, T_in_V, &m, moved_above);
  report->rejected_in_claw += evidence::DropInsideClaw(record, T_in_V, &m, moved_above);
  report->mirror_lift_m = cap_z_V - image_top.cap_z_V;
  char text[112];
  std::snprintf(text, sizeof(text), "; its top raised %.1f mm to where the rays %s",
                1000.0 * report->mirror_lift_m, carved ? "carve it" : "carve the top's outline");
  symmetry->reason += text;
}

// The evidence's top keeps its points only where the image has none
// within `layer`, 2 spacings (under the claw, past the image's outline).
// Cutting the image at the top band and adding the evidence's top
// instead left the image's cap 1-2 mm under the evidence's as a second
// layer wherever the phantom layer over the top edge raised the band
// (a cuboid: 7% of its cloud over 1.2 mm from its collision mesh).
// A dome keeps its points only in the columns the image leaves open
// (the image's top is the sharper surface where it has one).
void DropTopPointsUnderImage(const PointList& image_V, double layer, bool dome, PointList* top_V) {
  PointList flat;
  if (dome) {
    for (const Eigen::Vector3f& p : image_V) flat.emplace_back(p.x(), p.y(), 0.0f);
  }
  const NeighborIndex image(dome ? flat : image_V);
  PointList& t = *top_V;
  t.erase(std::remove_if(t.begin(), t.end(),
                         [&](const Eigen::Vector3f& p) {
                           return image.AnyWithin(dome ? Eigen::Vector3f(p.x(), p.y(), 0.0f) : p, layer);
                         }),
          t.end());
}

}  // namespace

const evidence::VisibilityRecord* UsableRecord(const ObjectCloud& input,
                                               const evidence::VisibilityRecord* record,
                                               const RepairSettings& config, EvidenceReport* report) {
  if (!record) return nullptr;
  report->key_frames = static_cast<int>(record->size());
  if (config.mode == RepairMode::kPaper) {
    report->ignored_reason = "paper mode repairs from the cloud alone";
    return nullptr;
  }
  if (record->empty()) {
    report->ignored_reason = "the record holds no key frame";
    return nullptr;
  }
  report->observed_free_share = evidence::ObservedSeenFreeShare(*record, input, kRecordCheckPoints);
  if (report->observed_free_share > config.evidence.max_observed_free_share) {
    report->ignored_reason = "the record does not match the cloud: " +
                             std::to_string(static_cast<int>(100.0 * report->observed_free_share + 0.5)) +
                             "% of the observed points lie in its seen-free space (another frame or object?)";
    return nullptr;
  }
  report->used = true;
  return record;
}

EvidenceTopPoints ApplyEvidence(const evidence::VisibilityRecord& record, const EvidenceConfig& config,
                                const Eigen::Isometry3f& T_in_V, const NeighborIndex& index_V,
                                double spacing_m, PointList* surface_V, SymmetryResult* symmetry,
                                EvidenceReport* report) {
  CheckClawFills(record, T_in_V, surface_V, report);
  report->mirror_free_share = std::numeric_limits<double>::quiet_NaN();
  if (symmetry->symmetric) TestMirrorAgainstRecord(record, config, T_in_V, index_V, symmetry, report);
  // The mirror closes low: the walls are seen only up to a few mm below
  // the top, and the plane is the middle of what was seen. Its top 2 x
  // top_band_m are stretched so that its cap (the median height of its top
  // layer, not its highest point) rises to the top the rays give: first
  // its own cap's, raised until they carve it.
  PointList& m = symmetry->added_V;
  const bool mirrored = symmetry->symmetric && !m.empty();
  const double layer = 2.0 * spacing_m;
  const ImageTop image_top = mirrored ? TopOfImage(m, layer) : ImageTop{};
  const float carved_top = mirrored ? CarvedImageTop(record, config, T_in_V, image_top, m)
                                    : std::numeric_limits<float>::quiet_NaN();
  bool carved = !std::isnan(carved_top);
  // With a mirror, a dome is refitted over the cloud and the image below.
  EvidenceTop top = CloseTopFromEvidence(index_V, *surface_V, record, T_in_V, spacing_m, config, mirrored);
  EvidenceTopPoints result = OutcomeAndExtrusion(top);
  if (mirrored && top.outcome == TopEvidence::kDome) {
    RefitDomeWithImage(record, config, T_in_V, index_V, spacing_m, *surface_V, m, &top);
  }
  const bool rings_agree = carved && RingsConfirmTheCarve(top, carved_top, config);
  if (rings_agree) carved = false;
  report->top = TopEvidenceName(top.outcome);
  report->top_above_wall_m = top.top_z_V - top.wall_top_z_V;
  if (mirrored) {
    const ImageCap cap = ChooseImageCap(image_top, carved_top, carved, rings_agree, top, config);
    if (cap.z_V > image_top.cap_z_V) {
      RaiseImageCap(record, config, T_in_V, image_top, cap.z_V, carved, symmetry, report);
    }
    // The mirror's top holds, but for a dome: the image of a bottom the
    // camera never saw leaves a round top's middle open.
    if (!cap.keep_evidence_top && top.outcome != TopEvidence::kDome) return result;
    DropTopPointsUnderImage(m, layer, top.outcome == TopEvidence::kDome, &top.added_V);
  }
  report->rejected_free += top.rejected_free;
  const int in_claw = evidence::DropInsideClaw(record, T_in_V, &top.added_V);
  report->rejected_in_claw += in_claw;
  report->top_points_added = static_cast<int>(top.added_V.size());
  result.points_V = std::move(top.added_V);
  result.dome = std::move(top.dome);
  result.rejected = top.rejected_free + in_claw;
  return result;
}

}  // namespace graspfill::repair
