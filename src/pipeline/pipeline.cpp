// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/pipeline/pipeline.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "graspfill/core/openmp_threads.hpp"
#include "graspfill/core/pose_interpolation.hpp"
#include "graspfill/evidence/seen_free_carve.hpp"
#include "graspfill/fusion/depth_edges.hpp"

namespace graspfill {
namespace {

FrameSkipReason SkipReasonOf(refine::RefineOutcome outcome) {
  switch (outcome) {
    case refine::RefineOutcome::kClawNotSeen:
      return FrameSkipReason::kClawNotSeen;
    case refine::RefineOutcome::kNotConverged:
      return FrameSkipReason::kRefineNotConverged;
    case refine::RefineOutcome::kJump:
      return FrameSkipReason::kRefineJump;
    default:
      return FrameSkipReason::kNone;
  }
}

FrameSkipReason SkipReasonOf(refine::TrackOutcome outcome) {
  switch (outcome) {
    case refine::TrackOutcome::kTooFewPoints:
      return FrameSkipReason::kTrackTooFewPoints;
    case refine::TrackOutcome::kNotConverged:
      return FrameSkipReason::kTrackNotConverged;
    case refine::TrackOutcome::kJump:
      return FrameSkipReason::kTrackJump;
    default:
      return FrameSkipReason::kNone;
  }
}

}  // namespace

void PipelineConfig::Validate() const {
  workspace.Validate();
  tsdf.Validate();
  visibility.Validate();
  refine.Validate();
  track_object.Validate();
  if (max_pose_gap_us <= 0) throw std::invalid_argument("PipelineConfig: max_pose_gap_us <= 0");
  if (state_buffer_capacity < 2) throw std::invalid_argument("PipelineConfig: state_buffer_capacity < 2");
  if (max_pending_frames < 1) throw std::invalid_argument("PipelineConfig: max_pending_frames < 1");
  CheckOpenMpThreads("PipelineConfig: num_threads", num_threads);
  if (!(claw_rebuild_tolerance >= 0.0))
    throw std::invalid_argument("PipelineConfig: claw_rebuild_tolerance < 0");
  if (max_fusion_pixels < 1) throw std::invalid_argument("PipelineConfig: max_fusion_pixels < 1");
  if (mask.dilation_px < 0 || mask.roi_margin_px < 0 || !(mask.front_margin_m >= 0.0)) {
    throw std::invalid_argument("PipelineConfig: mask margins must be >= 0");
  }
}

struct Pipeline::Impl {
  Impl(const PipelineConfig& c, claw::ClawModel model)
      : config(c),
        claw(std::move(model)),
        mask(c.mask),
        fusion(c.tsdf),
        visibility(c.visibility, c.workspace),
        refiner(c.refine),
        tracker(c.track_object),
        states(static_cast<size_t>(c.state_buffer_capacity), c.max_pose_gap_us),
        pending(static_cast<size_t>(c.max_pending_frames)) {
    // A call decides at most the pending frames, one dropped and its own.
    decided.reserve(pending.size() + 2);
  }

  // Records what became of a frame.
  void Decide(int64_t utime, FrameSkipReason skip) {
    decided.push_back({utime, skip});
    if (skip != FrameSkipReason::kNone) stats.skipped.Count(skip);
  }

  // Rebuilds the claw scene when the fingers moved (setup-time work).
  void UpdateClaw(const GripperState& state) {
    bool changed = !claw_set || std::abs(state.opening_m - claw_opening_m) > config.claw_rebuild_tolerance ||
                   state.joint_values.size() != claw_joints.size();
    for (size_t i = 0; !changed && i < claw_joints.size(); ++i) {
      changed = std::abs(state.joint_values[i] - claw_joints[i]) > config.claw_rebuild_tolerance;
    }
    if (!changed) return;
    ScopedStageTimer t(&stats.claw_rebuild);
    const TriangleMesh posed = claw.Posed(state.opening_m, state.joint_values);
    mask.SetClaw(posed);
    visibility.SetClaw(posed);
    if (config.refine.enabled) refiner.SetClaw(posed);
    claw_opening_m = state.opening_m;
    claw_joints = state.joint_values;
    claw_set = true;
    ++stats.claw_rebuilds;
  }

  // `frame`, or its decimation (in `decimated`) when it has more pixels
  // than the config allows.
  const DepthFrame& WithinPixelLimit(const DepthFrame& frame) {
    const CameraIntrinsics& K = frame.intrinsics;
    int f = 1;
    while (int64_t{K.width / f} * (K.height / f) > config.max_fusion_pixels) ++f;
    if (f == 1) return frame;
    ++stats.frames_decimated;
    // Pixel (u', v') is pixel (f u', f v'): u = fx X / Z + cx becomes
    // u' = (fx / f) X / Z + cx / f.
    decimated.utime = frame.utime;
    decimated.intrinsics = {K.width / f, K.height / f, K.fx / f, K.fy / f, K.cx / f, K.cy / f};
    const int w = decimated.intrinsics.width, h = decimated.intrinsics.height;
    decimated.depth_m.resize(static_cast<size_t>(w) * h);
    for (int v = 0; v < h; ++v) {
      const float* row = frame.depth_m.data() + static_cast<size_t>(v) * f * K.width;
      float* out = decimated.depth_m.data() + static_cast<size_t>(v) * w;
      for (int u = 0; u < w; ++u) out[u] = row[static_cast<size_t>(u) * f];
    }
    return decimated;
  }

  // Refine the pose, crop, mask, track the object and fuse one frame; a
  // frame refinement or tracking rejects is counted, nothing fused, and
  // *skip says why.
  // `frame` with its depth divided by the scale the refinement found
  // (into `rescaled`), or `frame` itself while there is none.
  const DepthFrame& WithDepthScale(const DepthFrame& frame) {
    const double applied = refiner.depth_scale().applied;
    if (applied == 1.0) return frame;
    ScopedStageTimer t(&stats.depth_rescale);
    rescaled.utime = frame.utime;
    rescaled.intrinsics = frame.intrinsics;
    rescaled.depth_m.resize(frame.depth_m.size());
    const float inverse = static_cast<float>(1.0 / applied);
    for (size_t i = 0; i < frame.depth_m.size(); ++i) rescaled.depth_m[i] = frame.depth_m[i] * inverse;
    return rescaled;
  }

  FrameOutcome Integrate(const DepthFrame& raw_frame, const GripperState& state, FrameSkipReason* skip) {
    UpdateClaw(state);
    const DepthFrame& frame = WithDepthScale(raw_frame);
    Eigen::Isometry3d T_C_G = state.T_C_G;
    refine::RefineOutcome refined = refine::RefineOutcome::kOff;
    {
      ScopedStageTimer t(&stats.refine_time);
      refined = refiner.Refine(frame, state.T_C_G, &T_C_G);
      stats.refine = refiner.stats();
      if (!refine::Fuses(refined)) {
        ++stats.frames_skipped_refine;
        *skip = SkipReasonOf(refined);
        return FrameOutcome::kSkippedRefine;
      }
    }
    if (config.refine.enabled) {
      // This frame stays at the scale it was registered at; the next ones
      // get a new one.
      ScopedStageTimer t(&stats.depth_scale);
      refiner.CalibrateDepthScale();
      stats.refine = refiner.stats();
    }
    if (config.reject_depth_edges) {
      // Before the crop, which zeroes the background an edge pixel jumps to
      // (a zeroed neighbour says nothing); over the box's image only.
      ScopedStageTimer t(&stats.depth_edges);
      work.utime = frame.utime;
      work.intrinsics = frame.intrinsics;
      work.depth_m.assign(frame.depth_m.begin(), frame.depth_m.end());
      const fusion::PixelRect box = fusion::ProjectBox(config.workspace, T_C_G, work.intrinsics, 2);
      stats.depth_edge_pixels += fusion::RejectDepthEdges(box, &work, &edge_marks);
    }
    {
      // The crop writes the working copy (one pass over the frame), or crops
      // the one the edges were dropped from.
      ScopedStageTimer t(&stats.crop);
      if (config.reject_depth_edges) {
        fusion::CropToWorkspace(config.workspace, T_C_G, &work);
      } else {
        fusion::CropToWorkspace(config.workspace, T_C_G, frame, &work);
      }
    }
    {
      ScopedStageTimer t(&stats.mask);
      mask.Apply(T_C_G, &work);
    }
    // The camera in the volume's frame: G, or with tracking the object's
    // frame as first seen (the claw, crop and mask stay in G).
    Eigen::Isometry3d T_C_O = T_C_G;
    if (config.track_object.enabled) {
      ScopedStageTimer t(&stats.track_time);
      const refine::TrackOutcome outcome = tracker.Track(work, T_C_G);
      stats.tracking = tracker.stats();
      if (outcome != refine::TrackOutcome::kTracked && outcome != refine::TrackOutcome::kNoModel) {
        ++stats.frames_skipped_tracking;
        *skip = SkipReasonOf(outcome);
        return FrameOutcome::kSkippedTracking;
      }
      T_C_O = tracker.T_C_O(T_C_G);
    }
    {
      ScopedStageTimer t(&stats.integrate);
      fusion.Integrate(work, T_C_O);
    }
    {
      ScopedStageTimer t(&stats.visibility);
      // Not a frame its own registration moved off the prediction (unless
      // there is no deadband: every registration is then trusted): on an
      // exact recording those moves are the registration's error (up to
      // 1.4 mm), and a key frame 1 mm off carves the grazed edge of what
      // it looks past (a cereal box's top, 3.5 mm short).
      if (refined != refine::RefineOutcome::kRefined || !config.refine.has_deadband()) {
        visibility.Offer(frame, mask.claw_depth_m(), T_C_O);
      }
    }
    last_utime = frame.utime;
    last_T_C_G = T_C_O;
    ++stats.frames_integrated;
    if (config.track_object.enabled) {
      ScopedStageTimer t(&stats.track_time);
      UpdateTrackingModel();
      stats.tracking = tracker.stats();
    }
    return FrameOutcome::kIntegrated;
  }

  // The tracker's model: the surface fused so far, re-extracted after the
  // warm-up and every model_refresh_frames fused frames (an extraction
  // costs tens of ms; `model` keeps its memory between them).
  void UpdateTrackingModel() {
    const refine::ObjectTrackingConfig& c = tracker.config();
    const int fused = fusion.frames_integrated();
    if (fused < c.warmup_frames) return;
    if (tracker.has_model() && fused - model_frames < c.model_refresh_frames) return;
    fusion.ExtractCloud(&model);
    tracker.SetModel(model.points_G, model.normals_G);
    model_frames = fused;
  }

  // Tries the frame against the state buffer; records it when decided.
  FrameOutcome TryIntegrate(const DepthFrame& frame) {
    FrameSkipReason skip = FrameSkipReason::kNone;
    FrameOutcome outcome = FrameOutcome::kSkippedNoPose;
    switch (states.Lookup(frame.utime, &pose)) {
      case PoseLookup::kOk:
        outcome = Integrate(frame, pose, &skip);
        break;
      case PoseLookup::kNotYet:
        return FrameOutcome::kPending;
      case PoseLookup::kTooEarly:
        skip = FrameSkipReason::kNoPoseBefore;
        break;
      case PoseLookup::kGap:
        skip = FrameSkipReason::kPoseGap;
        break;
    }
    if (outcome == FrameOutcome::kSkippedNoPose) ++stats.frames_skipped_no_pose;
    Decide(frame.utime, skip);
    return outcome;
  }

  // Processes pending frames in arrival order while they can be decided.
  void DrainPending() {
    while (num_pending > 0) {
      const FrameOutcome outcome = TryIntegrate(pending[pending_head]);
      if (outcome == FrameOutcome::kPending) return;
      pending_head = (pending_head + 1) % pending.size();
      --num_pending;
    }
  }

  PipelineConfig config;
  claw::ClawModel claw;
  claw::ClawMask mask;
  fusion::TsdfFusion fusion;
  evidence::VisibilityRecord visibility;
  refine::PoseRefiner refiner;
  refine::ObjectTracker tracker;
  ObjectCloud model;    // the tracker's model, reused
  int model_frames{0};  // frames fused when it was extracted
  GripperStateBuffer states;
  std::vector<DepthFrame> pending;  // ring, slots reused
  size_t pending_head{0};
  size_t num_pending{0};
  DepthFrame decimated;             // a frame over max_fusion_pixels, decimated
  DepthFrame rescaled;              // a frame's depth divided by the scale found
  DepthFrame work;                  // the frame being cropped and masked
  std::vector<uint8_t> edge_marks;  // RejectDepthEdges' scratch, reused
  GripperState pose;                // interpolated state, reused
  bool claw_set{false};
  double claw_opening_m{0.0};
  std::vector<double> claw_joints;
  CameraIntrinsics first_intrinsics;
  bool have_intrinsics{false};
  int64_t last_utime{0};
  Eigen::Isometry3d last_T_C_G{Eigen::Isometry3d::Identity()};
  int64_t seq{0};
  PipelineStats stats;
  std::vector<FrameDecision> decided;  // by the last call; capacity reserved
};

Pipeline::Pipeline(const PipelineConfig& config, claw::ClawModel claw) {
  config.Validate();
  impl_ = std::make_unique<Impl>(config, std::move(claw));
}

Pipeline::~Pipeline() = default;

bool Pipeline::AddGripperState(const GripperState& state) {
  const ScopedOpenMpThreads threads(impl_->config.num_threads);
  impl_->decided.clear();
  ++impl_->stats.states_in;
  if (!impl_->states.Push(state)) {
    ++impl_->stats.states_rejected;
    return false;
  }
  impl_->DrainPending();
  return true;
}

FrameOutcome Pipeline::AddDepthFrame(const DepthFrame& full_frame, std::string* error) {
  Impl& s = *impl_;
  const ScopedOpenMpThreads threads(s.config.num_threads);
  s.decided.clear();
  ++s.stats.frames_in;
  const CameraIntrinsics& K = full_frame.intrinsics;
  const char* problem = nullptr;
  if (K.width <= 0 || K.height <= 0 || full_frame.depth_m.size() != static_cast<size_t>(K.width) * K.height) {
    problem = "depth size does not match width x height";
  } else if (!(K.fx > 0 && K.fy > 0 && std::isfinite(K.cx) && std::isfinite(K.cy))) {
    problem = "bad intrinsics";
  } else if (s.have_intrinsics &&
             (K.width != s.first_intrinsics.width || K.height != s.first_intrinsics.height)) {
    problem = "frame size differs from the first frame's";
  }
  if (problem) {
    ++s.stats.frames_bad;
    s.Decide(full_frame.utime, FrameSkipReason::kBadFrame);
    if (error) *error = problem;
    return FrameOutcome::kBadFrame;
  }
  if (!s.have_intrinsics) {
    s.first_intrinsics = K;
    s.have_intrinsics = true;
  }
  // Decimated before it waits, so that pending slots stay small too.
  const DepthFrame& frame = s.WithinPixelLimit(full_frame);
  // Keep arrival order: a frame waits behind earlier pending frames.
  if (s.num_pending == 0) {
    const FrameOutcome outcome = s.TryIntegrate(frame);
    if (outcome != FrameOutcome::kPending) return outcome;
  }
  if (s.num_pending == s.pending.size()) {  // full: drop the oldest
    s.Decide(s.pending[s.pending_head].utime, FrameSkipReason::kPendingFull);
    s.pending_head = (s.pending_head + 1) % s.pending.size();
    --s.num_pending;
    ++s.stats.frames_dropped;
  }
  DepthFrame& slot = s.pending[(s.pending_head + s.num_pending) % s.pending.size()];
  slot.utime = frame.utime;
  slot.intrinsics = frame.intrinsics;
  slot.depth_m.assign(frame.depth_m.begin(), frame.depth_m.end());
  ++s.num_pending;
  return FrameOutcome::kPending;
}

void Pipeline::Flush() {
  Impl& s = *impl_;
  const ScopedOpenMpThreads threads(s.config.num_threads);
  s.decided.clear();
  s.DrainPending();
  for (; s.num_pending > 0; --s.num_pending) {
    s.Decide(s.pending[s.pending_head].utime, FrameSkipReason::kNoPoseAfter);
    s.pending_head = (s.pending_head + 1) % s.pending.size();
    ++s.stats.frames_skipped_no_pose;
  }
}

ObjectCloud Pipeline::ExtractCloud() {
  Impl& s = *impl_;
  const ScopedOpenMpThreads threads(s.config.num_threads);
  ObjectCloud cloud;
  {
    ScopedStageTimer t(&s.stats.extract);
    s.fusion.ExtractCloud(&cloud);
  }
  {
    ScopedStageTimer t(&s.stats.carve);
    s.stats.points_carved_last = static_cast<int64_t>(evidence::CarveSeenFree(s.visibility, &cloud));
  }
  cloud.utime = s.last_utime;
  cloud.seq = s.seq++;
  cloud.T_C_G = s.last_T_C_G;
  cloud.timings = {{"crop", s.stats.crop.mean_ms()},           {"mask", s.stats.mask.mean_ms()},
                   {"integrate", s.stats.integrate.mean_ms()}, {"visibility", s.stats.visibility.mean_ms()},
                   {"extract", s.stats.extract.last_ms},       {"carve", s.stats.carve.last_ms}};
  return cloud;
}

void Pipeline::Reset() {
  Impl& s = *impl_;
  s.fusion.Reset();
  s.visibility.Reset();
  s.refiner.Reset();
  s.tracker.Reset();
  s.model_frames = 0;
  s.claw_set = false;  // the next state gives the record its claw again
  s.states =
      GripperStateBuffer(static_cast<size_t>(s.config.state_buffer_capacity), s.config.max_pose_gap_us);
  s.num_pending = 0;
  s.decided.clear();
  s.have_intrinsics = false;
  s.stats = PipelineStats{};
}

const evidence::VisibilityRecord& Pipeline::visibility() const { return impl_->visibility; }
const fusion::TsdfFusion& Pipeline::fusion() const { return impl_->fusion; }
const DepthFrame& Pipeline::last_fused_frame() const { return impl_->work; }
Eigen::Isometry3d Pipeline::last_fused_T_C_V() const { return impl_->last_T_C_G; }
const refine::PoseRefiner& Pipeline::refiner() const { return impl_->refiner; }
const refine::ObjectTracker& Pipeline::tracker() const { return impl_->tracker; }
Eigen::Isometry3d Pipeline::ObjectPose() const { return impl_->tracker.S_G(); }
const PipelineStats& Pipeline::stats() const { return impl_->stats; }
const std::vector<FrameDecision>& Pipeline::decided() const { return impl_->decided; }
const PipelineConfig& Pipeline::config() const { return impl_->config; }

}  // namespace graspfill
