// SPDX-License-Identifier: BSD-3-Clause
// The in-process grasp-reconstruction module: gripper states and depth
// frames go in (from a live camera or a recording, in any interleaving),
// the object's cloud in the gripper frame comes out.
//
// Per depth frame: decimated if it is very large, pose at the frame's
// timestamp (interpolated between the bracketing gripper states), refined by registering the claw to the
// depth (refine/pose_refiner.hpp; a frame it rejects is skipped), crop to the workspace box in G, claw
// cut-out by ray casting the posed claw, with object tracking on the object's pixels aligned to the model
// fused so far (refine/object_tracker.hpp: the object slipping in G; a frame it rejects is skipped), TSDF
// integration in G (in the object's frame as first seen, with tracking), and the frame offered to the
// visibility record (evidence/). Extraction is on demand.
//
// Single-threaded and NOT thread safe: rt/ owns the threads that feed it.
// Open3D's OpenMP inside a call uses config.num_threads (default 1).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "graspfill/claw/claw_mask.hpp"
#include "graspfill/claw/claw_model.hpp"
#include "graspfill/core/frame_skip.hpp"
#include "graspfill/core/stage_timer.hpp"
#include "graspfill/evidence/visibility_record.hpp"
#include "graspfill/fusion/tsdf_fusion.hpp"
#include "graspfill/fusion/workspace_crop.hpp"
#include "graspfill/refine/object_tracker.hpp"
#include "graspfill/refine/pose_refiner.hpp"
#include "graspfill/types.hpp"

namespace graspfill {

struct PipelineConfig {
  claw::ClawMaskConfig mask;
  fusion::WorkspaceBox workspace;
  /// Drop the pixels on depth edges before the crop (fusion/depth_edges.hpp):
  /// mixed (flying) pixels and the silhouette's grazing returns. Off by
  /// default: the fused clouds lie closer to the truth, but the repair,
  /// tuned on clouds with those returns, meets fewer of the scanned
  /// objects' targets with it (docs/measurements/2026-12-06-depth-edges.md).
  bool reject_depth_edges{false};
  fusion::TsdfConfig tsdf;
  /// The key frames the repair tests its proposals against (over the
  /// workspace box above).
  evidence::VisibilityConfig visibility;
  /// Pose refinement before the mask and the fusion (on by default; a frame
  /// it rejects is skipped and counted, see refine/pose_refiner.hpp).
  refine::RefineConfig refine;
  /// Object tracking after the mask (off by default; a frame it rejects is
  /// skipped and counted). On, the volume, the visibility record and the
  /// extracted cloud are in the object's frame as first seen (G before any
  /// slip); ObjectPose() says where the object is in G now.
  refine::ObjectTrackingConfig track_object;
  /// Two gripper states bracketing a depth frame may be at most this far
  /// apart [us]; otherwise the frame is skipped (no trustworthy pose).
  int64_t max_pose_gap_us{50000};
  /// Gripper states kept for interpolation (2.5 s at 100 Hz).
  int state_buffer_capacity{256};
  /// Depth frames kept while waiting for a gripper state after them; the
  /// oldest is dropped (and counted) when more arrive.
  int max_pending_frames{8};
  /// The claw's ray-casting scene is rebuilt when the opening moves by more
  /// than this [m] (or any joint value by more than this [rad or m]).
  double claw_rebuild_tolerance{0.0005};
  /// Frames with more pixels than this are decimated before anything else
  /// (every f-th pixel of every f-th row, f the smallest integer that
  /// brings them under it; intrinsics divided by f): a 1.5 mm voxel needs
  /// no finer sampling at the workspace's distance, and the frame path's
  /// time and the key frames' memory grow with the pixels. The default,
  /// 1280 x 1024, leaves VGA, 720p and 1024 x 1024 cameras as they are and
  /// takes a 4096 x 4096 stream at 1/4 (docs/input-limits-and-fuzzing.md).
  int64_t max_fusion_pixels{1280 * 1024};
  /// OpenMP threads of each call (Open3D's TSDF integration): 1 (default)
  /// runs everything on the calling thread, N > 1 at most N threads, 0
  /// OpenMP's own count (a thread per core). Applied per call and the
  /// caller's settings restored after it, on whichever thread calls
  /// (core/openmp_threads.hpp); no environment variable is needed. The
  /// cloud is the same bytes at any count.
  int num_threads{1};

  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

/// What became of a depth frame (FrameDecision: why, when skipped).
enum class FrameOutcome {
  kIntegrated,       ///< fused into the volume
  kPending,          ///< waiting for a later gripper state
  kSkippedNoPose,    ///< no gripper states close enough around its timestamp
  kBadFrame,         ///< wrong size or bad intrinsics: rejected
  kSkippedRefine,    ///< pose refinement rejected it (PipelineStats::refine says why)
  kSkippedTracking,  ///< object tracking rejected it (PipelineStats::tracking says why)
};

/// A depth frame decided: fused (skip kNone) or skipped, and why.
struct FrameDecision {
  int64_t utime{0};  ///< the frame's own stamp
  FrameSkipReason skip{FrameSkipReason::kNone};
  bool fused() const { return skip == FrameSkipReason::kNone; }
};

struct PipelineStats {
  int64_t frames_in{0};
  int64_t frames_integrated{0};
  int64_t frames_skipped_no_pose{0};
  int64_t frames_bad{0};
  int64_t frames_dropped{0};  ///< pending queue overflow
  int64_t states_in{0};
  int64_t states_rejected{0};  ///< non-finite / not newer than the last
  int64_t claw_rebuilds{0};
  /// Remaking the claw's tables when the fingers moved (cut-out, record,
  /// refinement): on the frame path of the frame that saw them move.
  StageTotal claw_rebuild;
  int64_t frames_skipped_refine{0};  ///< rejected by pose refinement
  int64_t frames_decimated{0};       ///< over max_fusion_pixels, fused decimated
  refine::RefineStats refine;        ///< corrections, residuals, rejections by reason
  StageTotal refine_time;            ///< claw registration (0 when refinement is off)
  /// The depth's scale from the claw (PoseRefiner::CalibrateDepthScale),
  /// and dividing the frames' depth by it once applied.
  StageTotal depth_scale;
  StageTotal depth_rescale;
  int64_t frames_skipped_tracking{0};  ///< rejected by object tracking
  refine::TrackStats tracking;         ///< object tracking by outcome
  StageTotal track_time;               ///< object tracking and its model updates (0 when off)
  StageTotal crop;
  StageTotal mask;
  StageTotal depth_edges;        ///< rejecting the pixels on depth edges
  int64_t depth_edge_pixels{0};  ///< pixels it dropped, over all frames
  StageTotal integrate;
  StageTotal visibility;  ///< the key-frame test (and copy, for a new one)
  StageTotal extract;
  /// Removing the fused points the record saw free (seen_free_carve.hpp),
  /// at each extraction, and how many the last one removed.
  StageTotal carve;
  int64_t points_carved_last{0};
  /// Every frame not fused, by reason (the frames_skipped_*, frames_bad
  /// and frames_dropped counters above are sums of these).
  FrameSkipCounts skipped;
};

class Pipeline {
 public:
  /// Throws std::invalid_argument on a bad config.
  Pipeline(const PipelineConfig& config, claw::ClawModel claw);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// Adds a gripper state (states must come in time order; older ones and
  /// non-finite poses are rejected and counted). Integrates any pending
  /// frames the new state brackets. Returns false if rejected.
  bool AddGripperState(const GripperState& state);

  /// Adds a depth frame. It is integrated at once if the states around its
  /// timestamp are known, else kept pending (see max_pending_frames).
  /// `error` (optional) receives the reason for kBadFrame.
  FrameOutcome AddDepthFrame(const DepthFrame& frame, std::string* error = nullptr);

  /// End of stream: pending frames with no later state are skipped.
  void Flush();

  /// The depth frames the last AddGripperState, AddDepthFrame or Flush
  /// decided, in arrival order, each fused or with the reason it was
  /// skipped. Every frame given is decided exactly once (a pending one by
  /// a later call), so a caller that reads this after each call sees every
  /// skipped frame's reason. Valid until the next call.
  const std::vector<FrameDecision>& decided() const;

  /// The object cloud fused so far (points, normals, all observed), in G,
  /// stamped with the last integrated frame's time and gripper pose.
  ObjectCloud ExtractCloud();

  /// What the camera saw of the object so far, in G (key frames; copying
  /// it is cheap and the copy stays valid after Reset).
  const evidence::VisibilityRecord& visibility() const;
  /// The TSDF volume (in G, or the object's frame with tracking).
  const fusion::TsdfFusion& fusion() const;
  /// The frame last fused as the volume took it (cropped to the workspace,
  /// the claw cut out) and the camera's pose in the volume's frame then:
  /// what a caller needs to integrate the same frames elsewhere (`graspfill
  /// bench` times Open3D on them). Read them right after a call that fused
  /// a frame (stats().frames_integrated grew): the next call reuses the
  /// frame's buffer.
  const DepthFrame& last_fused_frame() const;
  Eigen::Isometry3d last_fused_T_C_V() const;

  /// The pose refinement's state: the hand-eye correction found so far
  /// (T_C_G ~= H * T_C_G_logged), the last registration.
  const refine::PoseRefiner& refiner() const;
  /// The object tracking's state; ObjectPose: the object's pose in G,
  /// S_G (p_G = S_G * p in the volume's frame; identity without tracking).
  const refine::ObjectTracker& tracker() const;
  Eigen::Isometry3d ObjectPose() const;

  /// Forgets the object (volume, visibility, states, pending frames);
  /// keeps the claw.
  void Reset();

  const PipelineStats& stats() const;
  const PipelineConfig& config() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspfill
