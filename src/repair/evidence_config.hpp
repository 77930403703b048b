// SPDX-License-Identifier: BSD-3-Clause
// The repair with the camera's evidence (the pipeline path; not in the
// paper, which has the cloud alone). The visibility record (evidence/)
// says for any point whether a ray passed it; the repair uses that to
//  - refuse a mirror image that lies where the camera saw nothing (a mug's
//    handle, a nozzle): Bohg et al. 2011 ("Mind the gap") score symmetry
//    hypotheses against the free space the same way;
//  - drop every proposed point in seen-free space (none is ever added);
//  - find the height of a flat top: its outline, extruded up from the
//    highest observed wall, stays unseen until it passes the top, where the
//    rays that graze over the top edge carve it. The top lands between the
//    highest wall and the lowest carved ring (the walls are measured only
//    up to 3-4 mm below the top: the views are grazing under the palm).
//
// The record and its queries over points are src/evidence's; the repair's
// use of them is here: these settings, the mirror's lowering and lift
// (mirror_evidence.hpp), the top from the evidence (evidence_top.hpp), and
// the stage that chooses the record and composes them (evidence_stage.hpp).
// Pure and single-threaded. Points of the repair are in V; the record is in
// the input frame (G for the pipeline), T_in_V maps between them.
#pragma once

namespace graspfill::repair {

struct EvidenceConfig {
  /// The record is ignored, and the report says so, when more than this
  /// share of the observed points lie in its seen-free space: it is of
  /// another frame or object (a matching record: < 1%).
  double max_observed_free_share{0.10};
  /// A mirror image with more than this share of its points in seen-free
  /// space is refused (symmetric objects: < 2%; a mug: ~30%).
  double max_mirror_free_share{0.05};
  /// With the record, the cloud's outline check (SymmetryConfig::
  /// max_outline_mismatch, 5%) lets a mirror through up to this mismatch
  /// (or that one, if larger): the record then judges the image. A fused
  /// round fruit's outlines differ from their images by 5-7% (the fingers'
  /// dents, a lean); clearly asymmetric clouds stay refused by the cloud
  /// (a bowl: 14-16%).
  double max_outline_mismatch{0.10};
  /// A contradicted mirror image is first lowered: the plane of a prism-like
  /// shape is the middle of the observed height, and the fused cloud's
  /// phantom layer over the top edge (see `phantom_m`) raises it, so the
  /// mirrored bottom caps the object up to 2 x phantom_m too high, in the
  /// rays that passed over the top. The plane drops by steps of
  /// `top_step_m`, up to this, until the share above is met; the mirror is
  /// refused only when no such drop meets it (a handle stays contradicted
  /// at every height) [m].
  double max_plane_drop_m{0.004};
  /// Whether a mirror image stands too high, or contradicts the record at
  /// all, is asked of its points with no observed point at least as high
  /// within this [m]. Those beside the seen surface stand a little proud
  /// of it, where a near-grazing ray sees them free: a slightly asymmetric
  /// body's image stands 1-2 mm off its seen half in places, and counted,
  /// those sink the whole image. They are lowered
  /// with the rest and dropped where seen free. A cap over the highest
  /// seen points is counted: a box's, too high, is contradicted at its
  /// edges, 4-5 mm over the seen wall tops. 0 counts all.
  double near_observed_m{0.004};
  /// The top's outline is the 2D hull of the observed points within this
  /// of the highest one [m].
  double top_band_m{0.005};
  /// The search for the top starts this far below the highest observed
  /// point, and the wall's baseline below that [m]: a fused cloud can hold
  /// a phantom layer up to ~3 mm over a top edge the rays pass over (the
  /// TSDF's truncation band behind the wall, 6 mm x sin 25 deg).
  double phantom_m{0.004};
  /// Ring heights are tested in steps of this [m].
  double top_step_m{0.0005};
  /// ... up to this far above the highest observed point [m].
  double top_search_m{0.03};
  /// The top is where a ring's free share first exceeds both the share of
  /// the rings on the observed wall and that of the ring
  /// top_jump_window_m under it by this much ...
  double top_free_jump{0.15};
  /// ... [m] (at least one top_step_m).
  double top_jump_window_m{0.0015};
  /// A flat cap needs walls that rise straight to the top: the outline of
  /// the top band must keep at least this share of the area of the outline
  /// `taper_drop_m` lower (cans, boxes, a bottle's neck: ~1; a round top
  /// such as fruit: < 0.8, which a flat cap would cut through).
  double min_flat_area_ratio{0.85};
  double taper_drop_m{0.01};
  /// A tapered top is closed by a dome instead: a quadratic height field
  /// over V's x-y fitted to the observed points within this of the highest
  /// one, sampled inside the outline of those points where none of them
  /// lies within a spacing in x-y, if it explains them to 1.5 mm RMS (not
  /// a bowl's upright rim) and curves down on every side (a dome, not a
  /// saddle or a bowl) with its apex inside the outline; 0 = no dome [m].
  double dome_support_m{0.012};
  /// A mirrored top closing more than this below the evidence's top is
  /// replaced by the evidence's (flat) top [m] (when the image's own cap
  /// cannot be tested against the rays: see max_cap_free_share). Where
  /// the rays confirm the rings' top (it lies within ring_trust_m under
  /// the carve), the image rises to it from any depth, its points alone.
  double mirror_low_m{0.001};
  /// The mirror image's cap (its top layer) is raised while at most this
  /// share of it lies in seen-free space: the walls are seen only up to a
  /// few mm below the top, so the image of the bottom closes 1-4 mm low,
  /// and the rays that graze over the true top carve the cap once it
  /// passes it. The image's own outline, unlike the top band's hull, keeps
  /// a rounded edge's inset and ignores fins.
  double max_cap_free_share{0.01};
  /// The carve starts this far over the true top (a ray passing a point
  /// carves it only when it measured something free_margin behind: just
  /// over a face that is the face itself), so the cap lands this much
  /// under the highest uncarved lift [m].
  double carve_onset_m{0.0005};
  /// The cap is raised at most this far; when no step up to it is carved
  /// (no ray passes over the top) the evidence's ring top decides [m].
  double max_mirror_lift_m{0.008};
  /// The rings' top (on the top band's hull) is kept when it lies at most
  /// this under the carved cap (+ carve_onset_m): hull and image outline
  /// then agree, and the rings grazed from the side are the sharper test
  /// (a can's cap carves up to 2 mm over its top). Farther under, the hull
  /// is wider than the top (a rounded edge, fins) and the carve decides [m].
  double ring_trust_m{0.0015};
  /// The cap test needs at least this many points in the image's top
  /// layer (a flat cap: ~1,000-4,000; a round top ~100).
  int min_cap_points{50};

  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

}  // namespace graspfill::repair
