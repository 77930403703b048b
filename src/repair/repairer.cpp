// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/repair/repairer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "evidence/point_list_queries.hpp"
#include "evidence_stage.hpp"
#include "graspfill/core/openmp_threads.hpp"
#include "graspfill/core/stage_timer.hpp"
#include "graspfill/evidence/safe_bound.hpp"
#include "hole_fill.hpp"
#include "neighbor_index.hpp"
#include "repair_steps.hpp"
#include "revolution_fill.hpp"
#include "top_search.hpp"

namespace graspfill::repair {
namespace {

// A model's samples are added where no observed point or fill lies within
// this many spacings: a hole, not the gaps between seen points.
constexpr double kHoleSpacings = 3.0;

// A coin flip, for what nothing decides: the paper mode's mirrored points
// (no search weighs them), and at most for a lid over walls that run
// straight up to the rim (no view saw it, and a mouth would end the walls
// alike: a can and a cup with the same outside give byte-identical fused
// clouds, docs/measurements/2026-12-07-can-or-cup.md).
constexpr float kCoinFlipConfidence = 0.5f;

// Below this the neighbourhood statistics of every step are meaningless.
constexpr size_t kMinPoints = 200;

// Best mode on a reduced cloud: the full-resolution boundary test covers
// the voxels of the centroids flagged and of their nearest neighbours
// (itself and 8: the band along a rim, ~2 voxels wide; with 4 the top-oblique row lost its claw holes).
constexpr int kNearVoxels = 9;

// The paper's linking replaces the gap-direction one when it links this
// many times as many boundary points (see the boundary lines step).
// Measured: the prism in the parallel claw with refined pose errors 3.7x
// (61 of 407 points; its finger hole opens into the top; coverage 0.970
// -> 0.996 with the classification's rim-run rule), on the shape zoo at
// 60 frames the ball 3.5x (0.971 -> 0.988) and the prism box 13.5x; the
// bottle 2.1x, worse with it (21% of its added points wrong, none
// without). At 90 frames no object links less than half as many.
constexpr size_t kPlainLinkFactor = 3;

size_t LinkedPoints(const std::vector<BoundaryLine>& lines) {
  size_t n = 0;
  for (const BoundaryLine& line : lines) n += line.indices.size();
  return n;
}

// Axis-aligned box, in the input frame, of points given in V.
void BoxInInput(const PointList& points_V, const VirtualFrame& frame, HoleSummary* hole) {
  const Eigen::Isometry3f T = frame.T_in_V.cast<float>();
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : points_V) box.extend(T * p);
  if (box.isEmpty()) return;
  hole->box_min_G = box.min();
  hole->box_max_G = box.max();
}

// Normals for the points after the first `first_added` whose normal is
// not known: the plane through each one's nearest neighbours among all
// points (`index`'s: so a small patch borrows its rim's), turned away from
// the centroid, since a held object is roughly convex about it.
void AppendAddedNormals(size_t first_added, const std::vector<Eigen::Vector3f>& known_G,
                        const NeighborIndex* index, ObjectCloud* cloud) {
  constexpr int kNeighbors = 16;  // a few spacings: stable, yet follows a curve
  const PointList& points = cloud->points_G;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : points) centroid += p.cast<double>();
  centroid /= static_cast<double>(points.size());
  std::vector<int> unknown;
  for (size_t i = first_added; i < points.size(); ++i) {
    if (known_G[i - first_added].isZero()) unknown.push_back(static_cast<int>(i));
  }
  std::vector<Eigen::Vector3f> estimated;
  if (!unknown.empty()) {
    estimated = fill::EstimateNormals(*index, unknown, kNeighbors, centroid.cast<float>());
  }
  size_t next = 0;
  for (size_t i = first_added; i < points.size(); ++i) {
    const Eigen::Vector3f& known = known_G[i - first_added];
    cloud->normals_G.push_back(known.isZero() ? estimated[next++] : known);
  }
}

// Boundary points in no line and not in the rim, in clusters of at least
// 20 (4 mm apart at most): holes the linking missed (finger pads that open
// into the top, their sides never closed into a line). Their boxes (V),
// for the mirror to fill as it fills the claw holes no fit explained.
std::vector<Eigen::AlignedBox3f> LooseBoundaryBoxes(const PointList& points_V,
                                                    const std::vector<int>& boundary,
                                                    const std::vector<BoundaryLine>& lines,
                                                    const HoleBoundary* missing,
                                                    const NeighborIndex& index_V) {
  constexpr double kClusterRadiusM = 0.004;
  constexpr size_t kMinClusterPoints = 20;
  std::vector<char> taken(points_V.size(), 0);
  for (const BoundaryLine& l : lines) {
    for (int i : l.indices) taken[i] = 1;
  }
  if (missing) {
    for (int i : missing->source_indices) {
      if (i >= 0 && static_cast<size_t>(i) < taken.size()) taken[i] = 1;
    }
  }
  std::vector<char> loose(points_V.size(), 0);
  for (int i : boundary) loose[i] = !taken[i];
  std::vector<Eigen::AlignedBox3f> boxes;
  std::vector<int> queue, near;
  for (int seed : boundary) {
    if (!loose[seed]) continue;
    loose[seed] = 0;
    queue.assign(1, seed);
    Eigen::AlignedBox3f box;
    box.setEmpty();
    for (size_t q = 0; q < queue.size(); ++q) {
      box.extend(points_V[queue[q]]);
      index_V.Radius(points_V[queue[q]], kClusterRadiusM, &near);
      for (int j : near) {
        if (loose[j]) loose[j] = 0, queue.push_back(j);
      }
    }
    if (queue.size() >= kMinClusterPoints) boxes.push_back(box);
  }
  return boxes;
}

// The cloud is one the steps can take (its size, its extent); else the
// report says why, and the cloud comes back as it is.
bool Repairable(const PointList& points_G, RepairReport* report) {
  if (points_G.size() < kMinPoints) {
    report->status = RepairStatus::kTooFewPoints;
    report->status_detail =
        std::to_string(points_G.size()) + " of at least " + std::to_string(kMinPoints) + ", nothing repaired";
    return false;
  }
  // Bounded work (issue 12): past these limits the steps' grids and
  // thresholds (in meters) stop making sense; the cloud comes back as is.
  if (points_G.size() > kMaxRepairPoints) {
    report->status = RepairStatus::kOutOfRange;
    report->status_detail = std::to_string(points_G.size()) + " points, more than the " +
                            std::to_string(kMaxRepairPoints) + " the repair takes";
    return false;
  }
  if (const double extent = RobustBox(points_G).sizes().maxCoeff();
      !(extent >= kMinRepairExtentM && extent <= kMaxRepairExtentM)) {
    char text[160];
    std::snprintf(text, sizeof(text), "the cloud's extent %.3g m is outside %g..%g m", extent,
                  kMinRepairExtentM, kMaxRepairExtentM);
    report->status = RepairStatus::kOutOfRange;
    report->status_detail = text;
    return false;
  }
  return true;
}

// The steps' products, stage by stage (Repair below chains them).

// Steps 0-3, where the holes are: the points the later steps read (the
// input's, without its outliers), their boundary points and closed lines.
struct Boundaries {
  PointList points;
  std::vector<int> boundary;  // into points
  // Unoriented normals of the points the boundary test looked at first (a
  // large cloud's reduced copy): step 4b's side normals.
  std::vector<Eigen::Vector3f> normals;
  std::vector<BoundaryLine> lines;
  bool reduced{false};  // looked at on a reduced copy first
};

Boundaries FindBoundaries(const PointList& input_G, const RepairSettings& config, RepairReport* report) {
  Boundaries out;
  // 0. Best mode looks for the holes on ~8k voxel centroids of a large
  // cloud; the fills (7-8) read every input point.
  std::optional<NeighborIndex> all;
  AnalysisCloud analysis;
  {
    ScopedStageTimer t(&report->timings, "analysis_cloud");
    all.emplace(input_G);
    analysis = MakeAnalysisCloud(*all, config.analysis);
  }
  out.reduced = analysis.reduced();
  std::optional<NeighborIndex> analysis_index;
  if (analysis.reduced()) analysis_index.emplace(analysis.points);
  const NeighborIndex& work_index = analysis.reduced() ? *analysis_index : *all;
  const PointList& work = work_index.points();

  // 1. Outliers are kept in the output but not used to find or fill holes.
  // One kNN table serves the filter and then, restricted to the points it
  // keeps (the rows that lost a neighbour are queried afresh), the
  // boundary detection.
  std::optional<KnnTable> table;
  std::vector<int> kept;
  PointList& points = out.points;
  std::vector<char> work_kept(work.size(), 0);
  {
    ScopedStageTimer t(&report->timings, "outliers");
    table = work_index.AllKnn(std::max(config.outliers.nb_neighbors, config.boundary.k) + 1);
    kept = RemoveOutliers(*table, config.outliers);
    points.reserve(kept.size());
    for (int i : kept) {
      points.push_back(work[i]);
      work_kept[i] = 1;
    }
  }
  // The input points the later steps read: those of the kept centroids.
  PointList fill_points;
  std::vector<int> fill_of_input;  // input index -> fill_points index, or -1
  if (analysis.reduced()) {
    fill_of_input.assign(input_G.size(), -1);
    for (size_t i = 0; i < input_G.size(); ++i) {
      if (!work_kept[analysis.voxel_of[i]]) continue;
      fill_of_input[i] = static_cast<int>(fill_points.size());
      fill_points.push_back(input_G[i]);
    }
    report->outliers_ignored = static_cast<int>(input_G.size() - fill_points.size());
  } else {
    report->outliers_ignored = static_cast<int>(input_G.size() - kept.size());
  }
  // 2-3. Boundary points, then closed boundary lines.
  std::vector<int>& boundary = out.boundary;
  std::vector<BoundaryPointInfo> boundary_info;  // which side the hole is on
  {
    ScopedStageTimer t(&report->timings, "boundary_points");
    // Over the kept points; when the filter kept all, work's index is theirs.
    std::optional<NeighborIndex> kept_index;
    const NeighborIndex* index = &work_index;
    if (kept.size() < work.size()) {
      index = &kept_index.emplace(points);
      table = RestrictTable(*table, kept, *index);
    }
    boundary = DetectBoundaryPoints(*index, config.boundary, &out.normals, &boundary_info, &*table);
  }
  std::optional<NeighborIndex> full_index;
  if (analysis.reduced()) {
    // Again at full resolution, but only around the boundary the centroids
    // show (their voxels and their neighbours'): the rims come out as the
    // input samples them, for a tenth of the cost of testing every point.
    ScopedStageTimer t(&report->timings, "boundary_points_full");
    std::vector<char> near(work.size(), 0);
    for (int b : boundary) {
      const int* row = table->Row(static_cast<size_t>(b));
      for (int j = 0; j < std::min(table->k, kNearVoxels); ++j) near[kept[row[j]]] = 1;
    }
    std::vector<int> candidates;
    for (size_t i = 0; i < input_G.size(); ++i) {
      if (fill_of_input[i] >= 0 && near[analysis.voxel_of[i]]) candidates.push_back(fill_of_input[i]);
    }
    points = std::move(fill_points);
    // Without outliers the kept points are the input: its index serves.
    const NeighborIndex* full = &*all;
    if (report->outliers_ignored > 0) full = &full_index.emplace(points);
    boundary_info.clear();
    boundary = DetectBoundaryPoints(*full, config.boundary, nullptr, &boundary_info, nullptr, &candidates);
  }
  {
    ScopedStageTimer t(&report->timings, "boundary_lines");
    out.lines = LinkBoundaryPoints(points, boundary, config.link, &boundary_info);
    // The gap directions keep close holes apart, but one point whose
    // widest gap lies on the wrong side of a ragged rim can stop the only
    // line there is (the large can of `bench repair --pipeline`: its rim
    // and both claw holes, one line, lost; a prism box whose finger hole
    // opens into its top: 12 of 411 boundary points linked, 162 by the
    // paper's rule): then the paper's rule alone, when it links far more.
    if (kPlainLinkFactor * LinkedPoints(out.lines) <= boundary.size()) {
      std::vector<BoundaryLine> plain = LinkBoundaryPoints(points, boundary, config.link);
      if (!plain.empty() && LinkedPoints(plain) >= kPlainLinkFactor * LinkedPoints(out.lines)) {
        out.lines = std::move(plain);
      }
    }
  }
  report->boundary_points = static_cast<int>(boundary.size());
  report->boundary_lines = static_cast<int>(out.lines.size());
  return out;
}

// Step 4: the virtual frame V, its z towards the missing top; with the
// record and an up hint, V from the hint when the lines give none (or
// there are none). nullopt (the report says why) when there is no frame.
std::optional<VirtualFrame> FindFrame(const Boundaries& found, const RepairSettings& config,
                                      bool evidence_frame, RepairReport* report) {
  const PointList& points = found.points;
  std::optional<VirtualFrame> frame;
  if (found.lines.empty()) {
    frame = WithAxis(VirtualFrame{}, config.up_hint->normalized(), points);
  } else {
    ScopedStageTimer t(&report->timings, "virtual_frame");
    // All detected boundary points, not only the linked ones: measured 54/54
    // correct frames against 47/54 (6 shapes x 3 grasps x 3 seeds).
    PointList boundary_points;
    for (int i : found.boundary) boundary_points.push_back(points[i]);
    std::string reason;
    frame = EstimateVirtualFrame(points, boundary_points, config.frame,
                                 config.up_hint ? &*config.up_hint : nullptr, &reason);
    if (!frame && evidence_frame) {
      frame = WithAxis(VirtualFrame{}, config.up_hint->normalized(), points);
    }
    if (!frame) {
      report->status = RepairStatus::kNoFrame;
      report->status_detail = reason;
      return std::nullopt;
    }
  }
  if (config.axis.enabled) {
    // Also on V from the hint (the claw's axis): the object may hang tilted
    // in an oblique grasp.
    ScopedStageTimer t(&report->timings, "axis");
    const AxisRefinement axis = RefineAxis(found.normals, frame->T_in_V.linear().col(2), config.axis);
    if (axis.refined) frame = WithAxis(*frame, axis.axis, points);
  }
  if (found.reduced) {
    frame = WithAxis(*frame, frame->T_in_V.linear().col(2), points);  // origin, box: all points
  }
  return frame;
}

// Steps 5-6: the closed boundaries, classified; the missing top's is the
// first missing surface, or (best mode) the boundary points near V's top.
struct Holes {
  std::vector<HoleBoundary> classified;
  std::vector<HoleBoundary> claw;  // the claw holes among them
  HoleBoundary rim;                // the boundary points near V's top
  int top_index{-1};               // the top's among `classified`, or -1
  bool top_is_rim{false};
  const HoleBoundary* Top() const {
    if (top_is_rim) return &rim;
    return top_index >= 0 ? &classified[static_cast<size_t>(top_index)] : nullptr;
  }
};

Holes ClassifyHoles(const PointList& points_V, const Boundaries& found, const VirtualFrame& frame,
                    const RepairSettings& config, RepairReport* report) {
  Holes holes;
  {
    ScopedStageTimer t(&report->timings, "classify");
    holes.classified = ClassifyBoundaries(points_V, found.lines, config.classify);
  }
  {
    ScopedStageTimer t(&report->timings, "complete");
    CompleteBoundaries(&holes.classified, config.completion);
  }
  for (size_t k = 0; k < holes.classified.size(); ++k) {
    const HoleBoundary& h = holes.classified[k];
    if (h.kind == HoleKind::kClaw)
      holes.claw.push_back(h);
    else if (holes.top_index < 0)
      holes.top_index = static_cast<int>(k);
  }
  // Best mode: the rim is also every boundary point near the top of V.
  // On a fused cloud the linking can break the rim into pieces (a ragged
  // TSDF edge, claw slits), and step 5 then finds a few points of it or
  // none; steps 7-8 need only the rim's height and extent, not its order.
  if (config.top_rim_band_m > 0.0) {
    HoleBoundary& rim = holes.rim;
    rim.kind = HoleKind::kMissingSurface;
    rim.closed = true;
    for (int i : found.boundary) {
      if (points_V[i].z() >= frame.max_V.z() - config.top_rim_band_m) {
        rim.points_V.push_back(points_V[i]);
        rim.source_indices.push_back(i);
      }
    }
    const HoleBoundary* missing = holes.Top();
    if (rim.points_V.size() >= 3 && (!missing || rim.points_V.size() > missing->points_V.size())) {
      // Keep the completed line's points too (they close the claw mouths).
      if (missing) {
        rim.points_V.insert(rim.points_V.end(), missing->points_V.begin(), missing->points_V.end());
        rim.source_indices.insert(rim.source_indices.end(), missing->source_indices.begin(),
                                  missing->source_indices.end());
      }
      holes.top_is_rim = true;
    }
  }
  return holes;
}

// Step 7's product: the claw holes' fills (V), and the boxes of the holes
// no fit explained or no line took (the mirror's to fill, as the top is).
struct ClawFills {
  PointList surface_V;
  std::vector<Eigen::AlignedBox3f> open_holes_V;
};

ClawFills FillClawHoles(const PointList& points_V, const Boundaries& found, const Holes& holes,
                        const NeighborIndex& index_V, const RepairSettings& config, RepairReport* report) {
  ClawFills fills;
  const HoleBoundary* missing = holes.Top();
  fills.open_holes_V = LooseBoundaryBoxes(points_V, found.boundary, found.lines, missing, index_V);
  if (holes.claw.empty()) return fills;
  std::vector<size_t> left_open;
  fills.surface_V = RepairClawHoles(points_V, holes.claw, config.claw, nullptr, &index_V, &left_open);
  if (missing) DropFillsOnTheTop(missing->points_V, config.claw.max_inside_top_rim_m, &fills.surface_V);
  report->claw_holes_left_open = static_cast<int>(left_open.size());
  for (size_t k : left_open) {
    Eigen::AlignedBox3f box;
    box.setEmpty();
    for (const Eigen::Vector3f& p : holes.claw[k].points_V) box.extend(p);
    fills.open_holes_V.push_back(box);
  }
  return fills;
}

// Step 8: the missing top by symmetry, from the observed and surface points.
SymmetryResult MirrorTop(const PointList& points_V, const Holes& holes, const NeighborIndex& index_V,
                         bool with_record, const RepairSettings& config, ClawFills* fills,
                         RepairReport* report) {
  ScopedStageTimer t(&report->timings, "symmetry");
  SymmetryResult symmetry;
  if (!holes.Top()) {
    symmetry.reason = "no missing surface found";
    return symmetry;
  }
  // The claw fills first take the holes' dents out of the cross-sections.
  // A hole no fit explained (a finger's that opens into the top, two
  // faces at once) or no line took is the mirror's to fill, as the top is.
  // With the record the cloud's outline check is only a first sieve:
  // the record judges the image (ApplyEvidence).
  SymmetryConfig symmetry_config = config.symmetry;
  if (with_record) {
    symmetry_config.max_outline_mismatch =
        std::max(symmetry_config.max_outline_mismatch, config.evidence.max_outline_mismatch);
  }
  return RepairMissingSurface(points_V, *holes.Top(), symmetry_config, &index_V, &fills->surface_V,
                              config.mode == RepairMode::kBest ? &fills->open_holes_V : nullptr);
}

// The top's points (V), their normals where the completion gives them
// (else empty), and their confidence. A lid over straight walls
// (`undecided_lid`) closes a top the walls do not close towards: its
// points, and the mirror's in the missing surface's box or over it
// (`top_box_V`; not those that fill claw holes beside it), carry at most
// kCoinFlipConfidence.
struct TopCap {
  PointList points_V;
  std::vector<Eigen::Vector3f> normals_V;
  float confidence{0.0f};
  bool undecided_lid{false};
  Eigen::AlignedBox3f top_box_V;

  float Capped() const { return undecided_lid ? std::min(confidence, kCoinFlipConfidence) : confidence; }
  float MirroredAt(const Eigen::Vector3f& p_V) const {
    return top_box_V.contains(p_V) ? Capped() : confidence;
  }
};

// The camera's evidence: nothing in seen-free space, no contradicted
// mirror, the top at the rays' height (the mirror's raised to it, or a
// dome over a tapered top).
EvidenceTopPoints TopFromEvidence(const evidence::VisibilityRecord* record, const RepairSettings& config,
                                  const Eigen::Isometry3f& T_in_V, const NeighborIndex& index_V,
                                  double spacing_m, PointList* surface_V, SymmetryResult* symmetry,
                                  RepairReport* report) {
  if (!record) return {};
  ScopedStageTimer t(&report->timings, "evidence");
  return ApplyEvidence(*record, config.evidence, T_in_V, index_V, spacing_m, surface_V, symmetry,
                       &report->evidence);
}

// The surface of revolution that closes the top, where one explains the
// cloud: sampled wherever the cloud and the fills leave it open (the top,
// and a claw hole no fit closed); the points the record sees free are
// dropped (and counted), those in the claw moved onto its face.
TopCandidate RevolutionCandidate(const PointList& points_V, const PointList& rim_V, const PointList& fills_V,
                                 double spacing_m, const evidence::VisibilityRecord* record,
                                 const Eigen::Isometry3f& T_in_V, const RepairSettings& config) {
  TopCandidate c;
  c.family = TopFamily::kRevolution;
  c.parameters = 5;
  float low = std::numeric_limits<float>::infinity(), high = -low;
  for (const Eigen::Vector3f& p : points_V) low = std::min(low, p.z()), high = std::max(high, p.z());
  const std::optional<Revolution> surface =
      FitRevolution(points_V, high, config.symmetry.max_added_height_fraction * (high - low));
  // A model that misses the seen surface by more than "open" allows at the
  // rim cannot be the completion (a pear, a box): not sampled.
  if (!surface || rim_V.empty() || surface->rms_m > kOpenSigmas * spacing_m) return c;
  PointList taken = points_V;  // the observed points and the fills
  taken.insert(taken.end(), fills_V.begin(), fills_V.end());
  // The seam is scored on the surface sampled as the mirror's image is
  // (where the cloud leaves a spacing open); it adds only where the cloud
  // leaves a hole, not between the seen points.
  RevolutionSamples samples = SampleRevolution(*surface, low, spacing_m, kHoleSpacings * spacing_m, taken);
  for (size_t i = 0; i < samples.points_V.size(); ++i) {
    if (samples.in_hole[i]) c.points_V.push_back(samples.points_V[i]);
  }
  c.seam_V = std::move(samples.points_V);
  const size_t proposed = c.points_V.size();
  if (record && proposed > 0) {
    // Where it runs into a finger, the object touches the finger: onto its
    // face, as the claw fills are.
    const int dropped = evidence::DropSeenFree(*record, T_in_V, &c.points_V);
    c.free_share = static_cast<double>(dropped) / static_cast<double>(proposed);
    evidence::PushOutOfClaw(*record, T_in_V, &c.points_V);
  }
  // The surface's own normals: exact where a neighbourhood of new points
  // would only estimate them (and the estimate's kNN is the slow part).
  for (const Eigen::Vector3f& p : c.points_V) c.normals_V.push_back(surface->Normal(p));
  return c;
}

// The evidence's dome's own normals of `points_V` (V); empty without a dome.
std::vector<Eigen::Vector3f> DomeNormals(const EvidenceTopPoints& evidence_top, const PointList& points_V) {
  std::vector<Eigen::Vector3f> normals;
  if (!evidence_top.dome) return normals;
  for (const Eigen::Vector3f& p : points_V) normals.push_back(evidence_top.dome->Normal(p));
  return normals;
}

// Step 9: the missing top by one scored search (top_search.hpp) over the
// mirror (with its top), a surface of revolution, the evidence's dome and
// "open". The winner's points and confidence; the report says which won.
TopCap SearchTop(const PointList& points_V, const ClawFills& fills, SymmetryResult* symmetry,
                 EvidenceTopPoints evidence_top, double spacing_m, const evidence::VisibilityRecord* record,
                 const Eigen::Isometry3f& T_in_V, const RepairSettings& config, RepairReport* report) {
  ScopedStageTimer t(&report->timings, "top_search");
  // The rim: the observed points within two spacings of the highest (V's
  // z points at the missing top, so they border it). Not the classified
  // boundary line, which a finger's hole opening into the top can pull
  // down the side.
  PointList rim_V;
  float high = -std::numeric_limits<float>::infinity();
  for (const Eigen::Vector3f& p : points_V) high = std::max(high, p.z());
  for (const Eigen::Vector3f& p : points_V) {
    if (p.z() >= high - 2.0 * spacing_m) rim_V.push_back(p);
  }
  std::vector<TopCandidate> candidates;
  const bool mirrored = symmetry->symmetric && !symmetry->added_V.empty();
  if (mirrored) {
    TopCandidate mirror;
    mirror.family = TopFamily::kMirror;
    mirror.parameters = 1;  // the plane's height
    mirror.points_V = symmetry->added_V;
    mirror.points_V.insert(mirror.points_V.end(), evidence_top.points_V.begin(), evidence_top.points_V.end());
    const double free = report->evidence.mirror_free_share;
    mirror.free_share = std::isfinite(free) ? free : 0.0;
    candidates.push_back(std::move(mirror));
  } else if (evidence_top.outcome == TopEvidence::kDome && !evidence_top.points_V.empty()) {
    TopCandidate dome;
    dome.family = TopFamily::kDome;
    dome.parameters = 6;  // a quadratic height field
    dome.points_V = evidence_top.points_V;
    dome.normals_V = DomeNormals(evidence_top, dome.points_V);
    dome.free_share = static_cast<double>(evidence_top.rejected) /
                      static_cast<double>(evidence_top.rejected + evidence_top.points_V.size());
    candidates.push_back(std::move(dome));
  }
  if (record && !evidence_top.extrusion_V.empty() &&
      evidence_top.extrusion_rms_m <= kOpenSigmas * spacing_m) {
    // A prism: the top's outline explains the walls all the way down, so
    // its lid is that outline at the rays' height, weighed beside the
    // mirror. A cup narrows to its bottom and is not proposed (its walls
    // alone cannot tell its mouth from a lid).
    TopCandidate extrusion;
    extrusion.family = TopFamily::kExtrusion;
    // The lid's height, and the outline: the rim's own hull, fitted to the
    // rim it is then scored against (x, y per vertex that describes it to
    // a spacing). A mirror or a surface of revolution predicts the rim
    // from the rest of the cloud.
    extrusion.parameters = 1 + 2 * evidence_top.outline_vertices;
    extrusion.points_V = std::move(evidence_top.extrusion_V);
    const int rejected =
        evidence_top.extrusion_rejected + evidence::DropInsideClaw(*record, T_in_V, &extrusion.points_V);
    extrusion.free_share =
        static_cast<double>(rejected) / static_cast<double>(rejected + extrusion.points_V.size());
    candidates.push_back(std::move(extrusion));
  }
  candidates.push_back(
      RevolutionCandidate(points_V, rim_V, fills.surface_V, spacing_m, record, T_in_V, config));
  const TopChoice choice = ChooseTop(std::move(candidates), rim_V, fills.surface_V, spacing_m);
  const TopCandidate& best = choice.Best();
  report->top_completion = TopFamilyName(best.family);
  std::string scored;
  for (const TopCandidate& c : choice.candidates) {
    char text[128];
    if (c.family == TopFamily::kOpen) {
      std::snprintf(text, sizeof(text), "%sopen %.2f", scored.empty() ? "" : ", ", c.cost);
    } else {
      std::snprintf(text, sizeof(text), "%s%s %.2f: seal %.2f mm, %.1f%% free", scored.empty() ? "" : ", ",
                    TopFamilyName(c.family).c_str(), c.cost, 1000.0 * c.seal_m, 100.0 * c.free_share);
    }
    scored += text;
  }
  if (std::isfinite(evidence_top.extrusion_rms_m)) {
    char prism[64];
    std::snprintf(prism, sizeof(prism), "; the walls off a prism by %.2f mm",
                  1000.0 * evidence_top.extrusion_rms_m);
    symmetry->reason += prism;
  }
  symmetry->reason += "; the top: " + report->top_completion + " (costs " + scored + ")";
  if (best.family != TopFamily::kMirror) {
    symmetry->symmetric = false;
    symmetry->added_V.clear();
  }
  TopCap top;
  if (best.family != TopFamily::kMirror && best.family != TopFamily::kOpen) {
    top.points_V = best.points_V;
    top.normals_V = best.normals_V;
  }
  if (best.family == TopFamily::kMirror) {
    top.points_V = std::move(evidence_top.points_V);
    top.normals_V = DomeNormals(evidence_top, top.points_V);
  }
  top.confidence = choice.confidence;
  // A lid: the extrusion's, or the mirror's over a constant section (where
  // its image fills claw holes beside the top, the straight walls do imply
  // the walls there).
  top.undecided_lid = best.family == TopFamily::kExtrusion ||
                      (best.family == TopFamily::kMirror && symmetry->constant_section);
  // Open upwards: the evidence stretches the image's top up to the rays.
  top.top_box_V = Eigen::AlignedBox3f(
      symmetry->box_min_V,
      Eigen::Vector3f(symmetry->box_max_V.x(), symmetry->box_max_V.y(), std::numeric_limits<float>::max()));
  report->top_confidence = top.Capped();
  if (top.Capped() < top.confidence) {
    char text[160];
    std::snprintf(text, sizeof(text),
                  "; its lid over straight walls, never seen, as likely a mouth: confidence %.2f, not %.2f",
                  top.Capped(), top.confidence);
    symmetry->reason += text;
  }
  report->evidence.top_points_added = static_cast<int>(top.points_V.size());
  return top;
}

// The added points back in the input's frame, after the input's: the claw
// fills, the mirror image, the top; each with its provenance, confidence
// and (when the input has normals) a normal.
void AppendAdded(const ObjectCloud& input, const ClawFills& fills, const SymmetryResult& symmetry,
                 const TopCap& top, const Eigen::Isometry3f& T_in_V, const evidence::VisibilityRecord* record,
                 ObjectCloud* out, RepairReport* report) {
  for (const Eigen::Vector3f& p : fills.surface_V) {
    out->points_G.push_back(T_in_V * p);
    out->provenance.push_back(Provenance::kSurface);
    const bool hidden_by_claw =
        record && record->Classify(out->points_G.back()) == evidence::Visibility::kBehindClaw;
    out->confidence.push_back(hidden_by_claw ? 0.8f : 0.6f);
  }
  for (const Eigen::Vector3f& p : symmetry.added_V) {
    out->points_G.push_back(T_in_V * p);
    out->provenance.push_back(Provenance::kSymmetry);
    out->confidence.push_back(top.MirroredAt(p));
  }
  for (const Eigen::Vector3f& p : top.points_V) {
    out->points_G.push_back(T_in_V * p);
    out->provenance.push_back(Provenance::kSurface);
    out->confidence.push_back(top.Capped());
  }
  // Normals: the input's are kept; the added points get estimated ones
  // when the input had them (a planner wants one per point), else none.
  if (input.normals_G.size() != input.points_G.size() || input.normals_G.empty()) {
    out->normals_G.clear();
    return;
  }
  ScopedStageTimer t(&report->timings, "normals");
  // A top whose model has a surface (the surface of revolution) gives its
  // own; a flat cap's is V's axis (a bowl's cap: 27k points, 48 ms of kNN);
  // the other added points' come from their neighbours.
  std::vector<Eigen::Vector3f> known_G(out->points_G.size() - input.points_G.size(), Eigen::Vector3f::Zero());
  const size_t first_top = known_G.size() - top.points_V.size();
  if (top.normals_V.size() == top.points_V.size()) {
    for (size_t k = 0; k < top.points_V.size(); ++k)
      known_G[first_top + k] = T_in_V.linear() * top.normals_V[k];
  } else if (!top.points_V.empty()) {
    float cap_z = -std::numeric_limits<float>::infinity();
    for (const Eigen::Vector3f& p : top.points_V) cap_z = std::max(cap_z, p.z());
    const Eigen::Vector3f up_G = T_in_V.linear().col(2);
    for (size_t k = 0; k < top.points_V.size(); ++k) {
      if (top.points_V[k].z() == cap_z) known_G[first_top + k] = up_G;
    }
  }
  // All points' index, where a normal is still to find.
  std::optional<NeighborIndex> index;
  if (std::any_of(known_G.begin(), known_G.end(), [](const Eigen::Vector3f& n) { return n.isZero(); })) {
    index.emplace(out->points_G);
  }
  // The mirror's points: their source's normal, mirrored (the input's point
  // nearest to where each was mirrored from, about the plane z = h in V).
  // Where that is an added point, the neighbours' estimate.
  const double h = symmetry.symmetry_plane_z;
  if (index && std::isfinite(h)) {
    const Eigen::Vector3f up_G = T_in_V.linear().col(2);
    const size_t first_mirror = fills.surface_V.size();
    std::vector<int> nearest;
    std::vector<double> squared;
    for (size_t k = 0; k < symmetry.added_V.size(); ++k) {
      const Eigen::Vector3f& q = symmetry.added_V[k];
      index->Knn(T_in_V * Eigen::Vector3f(q.x(), q.y(), static_cast<float>(2.0 * h) - q.z()), 1, &nearest,
                 &squared);
      if (nearest.empty() || static_cast<size_t>(nearest[0]) >= input.points_G.size()) continue;
      const Eigen::Vector3f& n = input.normals_G[static_cast<size_t>(nearest[0])];
      known_G[first_mirror + k] = n - 2.0f * n.dot(up_G) * up_G;
    }
  }
  AppendAddedNormals(input.points_G.size(), known_G, index ? &*index : nullptr, out);
}

// The report's holes (in the input's frame), with the points added to each
// and their mean confidence (`added_confidence`: the added points', in
// AppendAdded's order: the fills, the mirror's, the top's).
void ReportHoles(const Holes& holes, const VirtualFrame& frame, const ClawFills& fills,
                 const float* added_confidence, const SymmetryResult& symmetry, const TopCap& top,
                 RepairReport* report) {
  for (const HoleBoundary& h : holes.classified) {
    if (h.kind == HoleKind::kMissingSurface && holes.top_is_rim) continue;  // reported as the rim
    HoleSummary s;
    s.kind = h.kind;
    s.boundary_points = static_cast<int>(h.points_V.size());
    BoxInInput(h.points_V, frame, &s);
    report->holes.push_back(s);
  }
  if (holes.top_is_rim) {
    HoleSummary s;
    s.kind = HoleKind::kMissingSurface;
    s.boundary_points = static_cast<int>(holes.rim.points_V.size());
    BoxInInput(holes.rim.points_V, frame, &s);
    report->holes.insert(report->holes.begin(), s);
  }
  // Each fill point to the claw hole whose box centre is nearest.
  const Eigen::Isometry3f T_in_V = frame.T_in_V.cast<float>();
  for (size_t k = 0; k < fills.surface_V.size(); ++k) {
    const Eigen::Vector3f p_in = T_in_V * fills.surface_V[k];
    int best = -1;
    float best_d = 0.0f;
    for (size_t i = 0; i < report->holes.size(); ++i) {
      if (report->holes[i].kind != HoleKind::kClaw) continue;
      const float d = (0.5f * (report->holes[i].box_min_G + report->holes[i].box_max_G) - p_in).norm();
      if (best < 0 || d < best_d) best = static_cast<int>(i), best_d = d;
    }
    if (best < 0) continue;
    HoleSummary& hole = report->holes[best];
    // The running mean of its points' confidence.
    hole.confidence += (added_confidence[k] - hole.confidence) / static_cast<float>(++hole.points_added);
  }
  // The top's points follow the fills.
  const size_t top_points = symmetry.added_V.size() + top.points_V.size();
  double top_sum = 0.0;
  for (size_t k = 0; k < top_points; ++k) top_sum += added_confidence[fills.surface_V.size() + k];
  const float top_mean =
      top_points > 0 ? static_cast<float>(top_sum / static_cast<double>(top_points)) : 0.0f;
  const auto missing_hole =
      std::find_if(report->holes.begin(), report->holes.end(),
                   [](const HoleSummary& h) { return h.kind == HoleKind::kMissingSurface; });
  if (missing_hole != report->holes.end()) {
    missing_hole->points_added = static_cast<int>(top_points);
    missing_hole->unobserved = report->top_completion == TopFamilyName(TopFamily::kOpen);
    missing_hole->confidence = top_mean;
  } else if (!top.points_V.empty()) {
    // The evidence found the top the cloud's boundaries did not show.
    HoleSummary s;
    s.kind = HoleKind::kMissingSurface;
    BoxInInput(top.points_V, frame, &s);
    s.points_added = static_cast<int>(top.points_V.size());
    s.confidence = top_mean;
    report->holes.insert(report->holes.begin(), s);
  }
}

}  // namespace

std::string RepairStatusName(RepairStatus status) {
  switch (status) {
    case RepairStatus::kRepaired:
      return "repaired";
    case RepairStatus::kNoHoles:
      return "no holes found";
    case RepairStatus::kTooFewPoints:
      return "too few points";
    case RepairStatus::kNoFrame:
      return "no virtual frame";
    case RepairStatus::kOutOfRange:
      return "outside the repair's limits";
  }
  return "no holes found";
}

std::string RepairReport::StatusText() const {
  return status_detail.empty() ? RepairStatusName(status) : RepairStatusName(status) + ": " + status_detail;
}

void RepairConfig::Validate() const {
  if (!(safe_bound_voxel_m == 0.0 || (safe_bound_voxel_m >= 0.0005 && safe_bound_voxel_m <= 0.1))) {
    throw std::invalid_argument("RepairConfig: safe_bound_voxel_m must be 0 or in [0.0005, 0.1] m");
  }
  if (!(top_rim_band_m >= 0.0 && top_rim_band_m < 1.0)) {
    throw std::invalid_argument("RepairConfig: top_rim_band_m must be in [0, 1) m");
  }
  if (up_hint && (!up_hint->allFinite() || up_hint->norm() < 1e-9)) {
    throw std::invalid_argument("RepairConfig: up_hint must be a finite non-zero vector");
  }
  CheckOpenMpThreads("RepairConfig: num_threads", num_threads);
}

RepairSteps RepairSteps::For(RepairMode mode) {
  RepairSteps steps;
  if (mode == RepairMode::kPaper) {
    // The published parameters, not graspfill's refinements.
    steps.claw = ClawRepairConfig::Paper();
    steps.symmetry = SymmetryConfig::Paper();
    steps.axis.enabled = false;
    steps.frame.max_boundary_axis_angle_rad = 0.0;
    steps.analysis.target_points = 0;
  }
  return steps;
}

void RepairSteps::Validate() const {
  analysis.Validate();
  outliers.Validate();
  boundary.Validate();
  link.Validate();
  frame.Validate();
  classify.Validate();
  completion.Validate();
  claw.Validate();
  symmetry.Validate();
  evidence.Validate();
}

RepairResult Repair(const ObjectCloud& input, const RepairConfig& config,
                    const evidence::VisibilityRecord* record) {
  return RepairWithSteps(input, config, RepairSteps::For(config.mode), record);
}

RepairResult RepairWithSteps(const ObjectCloud& input, const RepairConfig& config_in,
                             const RepairSteps& steps, const evidence::VisibilityRecord* record_in) {
  RepairSettings config;
  static_cast<RepairConfig&>(config) = config_in;
  static_cast<RepairSteps&>(config) = steps;
  if (config.mode == RepairMode::kPaper) config.top_rim_band_m = 0.0;  // step 5's rim alone
  config.RepairConfig::Validate();
  config.RepairSteps::Validate();
  const ScopedOpenMpThreads threads(config.num_threads);
  for (size_t i = 0; i < input.points_G.size(); ++i) {
    if (!input.points_G[i].allFinite()) {
      throw std::invalid_argument("repair: point " + std::to_string(i) + " is not finite");
    }
  }
  RepairResult result;
  result.cloud = input;
  result.cloud.holes.clear();  // this repair's holes, set at the end
  result.cloud.provenance.resize(input.points_G.size(), Provenance::kObserved);
  RepairReport& report = result.report;
  result.cloud.confidence.clear();
  if (!input.confidence.empty() && input.confidence.size() == input.points_G.size()) {
    result.cloud.confidence = input.confidence;
  } else {
    result.cloud.confidence.assign(input.points_G.size(), 1.0f);
  }
  const evidence::VisibilityRecord* record = UsableRecord(input, record_in, config, &report.evidence);
  if (record && config.safe_bound_voxel_m > 0.0) {
    ScopedStageTimer t(&report.timings, "safe_bound");
    evidence::SafeBoundConfig bound;
    bound.voxel_m = config.safe_bound_voxel_m;
    result.cloud.safe_bound = evidence::ComputeSafeBound(*record, bound);
    report.evidence.safe_bound_voxels = static_cast<int>(result.cloud.safe_bound.count());
  }
  if (!Repairable(input.points_G, &report)) return result;

  // 0-3. Where the holes are.
  const Boundaries found = FindBoundaries(input.points_G, config, &report);
  // With evidence a cloud whose holes the boundary test misses (a can's
  // whole lid, a clean cut) still gets its top: V from the up hint.
  const bool evidence_frame = record && config.up_hint;
  if (found.lines.empty() && !evidence_frame) {
    report.status = RepairStatus::kNoHoles;
    return result;
  }
  // 4. The virtual frame V.
  const std::optional<VirtualFrame> frame = FindFrame(found, config, evidence_frame, &report);
  if (!frame) return result;
  report.frame = *frame;
  const PointList points_V = ToVirtualFrame(found.points, *frame);
  // 5-6. Missing surface vs claw holes, then closed boundaries.
  const Holes holes = ClassifyHoles(points_V, found, *frame, config, &report);
  // 7. Claw holes from a reconstructed surface.
  std::optional<NeighborIndex> index_V;  // the steps from here on share it
  ClawFills fills;
  {
    ScopedStageTimer t(&report.timings, "claw_holes");
    index_V.emplace(points_V);
    fills = FillClawHoles(points_V, found, holes, *index_V, config, &report);
  }
  // 8. The mirror image of the far end, and the evidence's top: the mirror
  // raised to the rays, or a dome.
  SymmetryResult symmetry = MirrorTop(points_V, holes, *index_V, record != nullptr, config, &fills, &report);
  const Eigen::Isometry3f T_in_V = frame->T_in_V.cast<float>();
  const double spacing_m = MeanNearestDistance(*index_V, config.symmetry.spacing_samples);
  EvidenceTopPoints evidence_top =
      TopFromEvidence(record, config, T_in_V, *index_V, spacing_m, &fills.surface_V, &symmetry, &report);
  // 9. The top: the search (best mode) or the mirror as it is (the paper).
  TopCap top;
  if (config.mode == RepairMode::kBest) {
    top = SearchTop(points_V, fills, &symmetry, std::move(evidence_top), spacing_m, record, T_in_V, config,
                    &report);
  } else {
    top.confidence = kCoinFlipConfidence;
  }
  report.symmetric = symmetry.symmetric;
  report.symmetry_reason = symmetry.reason;

  AppendAdded(input, fills, symmetry, top, T_in_V, record, &result.cloud, &report);
  // The fills' confidences follow the input's in the output (AppendAdded).
  ReportHoles(holes, *frame, fills, result.cloud.confidence.data() + input.points_G.size(), symmetry, top,
              &report);
  report.status = result.cloud.points_G.size() > input.points_G.size() || !found.lines.empty()
                      ? RepairStatus::kRepaired
                      : RepairStatus::kNoHoles;
  result.cloud.holes = report.holes;
  return result;
}

}  // namespace graspfill::repair
