// SPDX-License-Identifier: BSD-3-Clause
// The replay session, composed: a recorded LCM log (LcmLogSource, decoded
// ahead on a thread of its own) -> SequencerFeed -> GraspSequencer (made at
// the first depth or gripper event, once the session description at the
// recording's head is known) -> each grasp's final model delivered: hole
// repair -> PLY -> LcmPublisher, then the output's collision mesh (when
// asked for) -> LcmPublisher. rt::LiveSession is its live counterpart;
// `graspfill replay` only parses its flags, picks the claw and reports.
//
// The recording's session description gives the workspace box and the
// voxel unless the caller fixes them (a rig config, the command line), and
// its values must be within the config file's limits (as on the bus).
//
// Grasp after grasp: every grasp's model is delivered once the whole log
// is fused, in the order the grasps ended. The last grasp's model is the
// output; each earlier one goes beside it (GraspModelPath), so that no
// grasp's model replaces another's.
//
// Threads: one. Run fuses, repairs, writes and publishes on the caller's
// thread; only the log's decoding runs ahead on the source's own.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "graspfill/io/messages.hpp"
#include "graspfill/mesh/planner_mesh.hpp"
#include "graspfill/pipeline/pipeline.hpp"
#include "graspfill/repair/repairer.hpp"
#include "module/grasp_sequencer.hpp"
#include "module/sequencer_feed.hpp"
#include "sinks/lcm_publisher.hpp"
#include "sources/lcm_log_source.hpp"

namespace graspfill::rt {

/// Picks the claw once the recording's head is read. `session` is the
/// recording's first session description, if it came before the first
/// depth or gripper event. May throw: Run lets it out.
using ReplayClawChooser =
    std::function<claw::ClawModel(const std::optional<io::SessionDescription>& session)>;

struct ReplaySessionConfig {
  /// The recorded log (lcm-logger's format), its channels (object_cloud:
  /// where the models are published) and what the caller sets over its
  /// session descriptions (a rig config's hand-eye, intrinsics, clock
  /// offset, depth image limit). The session sets session_events: it reads
  /// the recording's description itself.
  LcmLogSource::Config log;
  /// Where the last grasp's model goes (PLY); each earlier grasp's goes
  /// beside it (GraspModelPath). Check it before the replay
  /// (io::CheckOutputFile), so that an output that cannot be written is
  /// found before the whole log is fused; an earlier grasp's path is
  /// checked when it is known.
  std::string output_path;
  /// Replace files that exist (a command's --force); false: one there is
  /// an error.
  bool overwrite{false};
  /// Publish each grasp's model over LCM (on log.channels.object_cloud)
  /// once it is written.
  bool publish{true};
  /// LCM URL to publish to ("" = LCM's default).
  std::string lcm_url;
  /// Count malformed events and go on; false: the first one ends the
  /// replay (ReplayEnd::kBadEvent).
  bool skip_bad_events{false};

  /// The pipeline. Its workspace box and voxel are replaced by the
  /// recording's session description's, unless fixed below.
  PipelineConfig pipeline;
  /// The caller's voxel (pipeline.tsdf) stands over the recording's.
  bool voxel_fixed{false};
  /// The caller's workspace box (pipeline.workspace) stands over the
  /// recording's.
  bool workspace_fixed{false};
  /// With the recording's voxel: the truncation distance, in voxels.
  double sdf_trunc_voxels{4.0};
  /// The claw (the CLI's --claw, the config's or the recording's);
  /// none: the three-finger claw.
  ReplayClawChooser choose_claw;

  /// Repair each grasp's model before it is written.
  bool repair{true};
  /// The repair's knobs; its up hint is G's (GripperFrameRepairConfig):
  /// replay fuses in the gripper frame.
  repair::RepairConfig repair_config;
  /// Repair with what the camera saw (the grasp's visibility record).
  bool repair_evidence{true};
  /// Keep the output's model as fused, before its repair
  /// (ReplayResult::output_fused; a picture of before and after). Only
  /// with the repair on.
  bool keep_output_fused{false};

  /// The output model's collision mesh for the planner
  /// (mesh/planner_mesh.hpp), made once the output is delivered and
  /// published as collision_mesh_t on log.channels.collision_mesh (with
  /// `publish`); none: no mesh.
  std::optional<mesh::PlannerMeshConfig> collision_mesh;

  /// Called about every progress_period_ms while the log is fused, on
  /// Run's thread, with the depth frames read so far; none: not called.
  std::function<void(int64_t depth_frames)> on_progress;
  int progress_period_ms{200};
};

/// How a replay ended. Every end but kDone is an error; ReplayResult says
/// more.
enum class ReplayEnd {
  kDone,                 ///< every grasp's model delivered
  kBadEvent,             ///< a malformed event, skip_bad_events off (error)
  kLogCorrupt,           ///< the log stops making sense before its end (error)
  kNoDepthFrames,        ///< no depth frame on channels.depth
  kRefineRejectedEvery,  ///< the pose refinement rejected every posed frame
  kNoPosedFrames,        ///< no depth frame had a gripper pose in time
  kDeliveryFailed,       ///< ReplayResult::grasps.back() says which step
};

/// Which model a delivery is, and so its error policy. The two differ on
/// purpose:
///  - the output was asked for by name, repaired (unless the repair is
///    off): an unrepaired cloud in its place would pass for what was asked,
///    so a failed repair stops its delivery (nothing written or published).
///    Its path was checked before the replay.
///  - an earlier grasp's model is still that grasp's model unrepaired, and
///    one grasp's failed repair should not cost the others theirs: it is
///    written and published as fused, the failure in its delivery. Its path
///    exists only once the grasps are known, so it is checked just before
///    the write.
/// A failed write stops either (and the replay).
enum class DeliveredModel { kEarlierGrasp, kOutput };

enum class DeliveryStep {
  kDelivered,     ///< repaired (or not, see repair_error), written, published
  kRepairFailed,  ///< the output's repair threw: nothing written
  kWriteFailed,   ///< the path could not be written: nothing published
};

/// One grasp's model: repaired -> written -> published.
struct GraspDelivery {
  DeliveredModel model{DeliveredModel::kOutput};
  DeliveryStep step{DeliveryStep::kDelivered};
  int64_t grasp_id{0};
  std::string path;
  size_t fused_points{0};  ///< before the repair
  size_t points{0};        ///< as written (the fused ones first)
  /// The repair's report; none when the repair is off or failed.
  std::optional<repair::RepairReport> repair;
  /// Why the repair failed ("" if it did not).
  std::string repair_error;
  /// Why the write failed ("" if it did not).
  std::string write_error;
  double repair_ms{0.0};
  double write_ms{0.0};
  double publish_ms{0.0};

  /// "off", the report's status, or "failed: <why>".
  std::string RepairStatusText() const;
};

struct ReplayResult {
  ReplayEnd end{ReplayEnd::kDone};
  /// kBadEvent: the first bad event; kLogCorrupt: where and why the log
  /// stops making sense.
  std::string error;

  /// The log, once read to its end.
  int64_t events_read{0};
  /// > 0: the log ends in a partial event of this many bytes (a recording
  /// cut short), skipped: a note, not an error.
  int64_t partial_event_bytes{0};
  std::vector<std::string> channels_seen;  ///< in order of first appearance

  /// The recording's first session description, if it came before the
  /// first depth or gripper event (the one used).
  std::optional<io::SessionDescription> session;
  int64_t sessions{0};
  /// Session descriptions that came later (their claw, box and voxel are
  /// not used), the first one's utime.
  int64_t late_sessions{0};
  int64_t late_session_utime{0};
  int64_t bad_events_skipped{0};

  /// Summed over the whole log (every grasp).
  PipelineStats stats;
  SessionCounters counters;

  /// In the order the grasps ended, the output's last; up to the one whose
  /// delivery failed.
  std::vector<GraspDelivery> grasps;
  /// The last grasp's model, as written (kDone).
  ObjectCloud output;
  /// The same as fused, before its repair (keep_output_fused).
  std::optional<ObjectCloud> output_fused;

  /// The output's collision mesh (config.collision_mesh, kDone), or why
  /// it could not be made (mesh_error; the replay's other outputs stand).
  std::optional<mesh::PlannerMesh> collision_mesh;
  std::string mesh_error;
  double mesh_ms{0.0};         ///< the mesh made (not its publication)
  bool mesh_published{false};  ///< LCM took the mesh (config.publish)

  double fuse_ms{0.0};     ///< the log read and fused
  double extract_ms{0.0};  ///< the last grasp's model extracted
};

/// Where an earlier grasp's model goes, beside the output OUT/STEM.EXT:
/// STEM.grasp<ID>.EXT for the first grasp with that id, and
/// STEM.grasp<ID>-<N>.EXT for its N-th (N >= 2; a robot that numbers its
/// grasps 1, 2, 1, 2).
std::string GraspModelPath(const std::string& output_path, int64_t grasp_id, int occurrence);

class ReplaySession {
 public:
  /// Opens the log.
  /// @throws std::runtime_error (LcmLogSource's) on a file that is not a
  ///   readable LCM log.
  explicit ReplaySession(ReplaySessionConfig config);
  ~ReplaySession();
  ReplaySession(const ReplaySession&) = delete;
  ReplaySession& operator=(const ReplaySession&) = delete;

  /// Fuses the whole log, then delivers every grasp's model; once.
  /// Lets out what the claw chooser throws, a session description beyond
  /// the limits (std::runtime_error), and the publisher's errors.
  ReplayResult Run();

  /// The last grasp's pipeline (its refinement and tracking stats), null
  /// before the first depth or gripper event.
  const Pipeline* pipeline() const;

 private:
  /// The sequencer for the recording's head (SequencerFeed's factory).
  std::unique_ptr<GraspSequencer> MakeSequencer(const std::optional<io::SessionDescription>& session);
  /// The one delivery: see DeliveredModel for its error policy.
  GraspDelivery Deliver(ObjectCloud* model, const evidence::VisibilityRecord& seen, const std::string& path,
                        DeliveredModel which);
  /// The output's collision mesh into *result, published (config_.publish).
  void MakeCollisionMesh(ReplayResult* result);

  /// A grasp's final model and what the camera saw of it.
  struct EndedGrasp {
    ObjectCloud cloud;
    evidence::VisibilityRecord seen;
  };

  ReplaySessionConfig config_;
  const LcmLogSource* log_{nullptr};  // inside source_ (which sets it: declared before it)
  std::unique_ptr<FrameSource> source_;
  SequencerFeed feed_;
  std::vector<EndedGrasp> ended_;
  std::unique_ptr<LcmPublisher> publisher_;  // made at the first publish
};

}  // namespace graspfill::rt
