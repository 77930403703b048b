// SPDX-License-Identifier: BSD-3-Clause
// The live grasp-and-model session, composed: sources (the LCM bus's
// gripper states and session descriptions, depth from the bus or from a
// FrameSource such as an OpenNI2 device) -> GraspModule (fusion worker,
// grasp after grasp) -> RepairStage (repair thread; grasp finals never
// superseded) -> LcmPublisher (clouds, status), with an optional
// SessionRecorder beside the module. `graspfill live` only parses its flags
// and wires one of these.
//
// Life: construct (subscribes; events are held until Begin), optionally
// WaitForFirstEvent (for the claw of the session description before the
// first depth frame), Begin (with the claw and the description the session
// runs with), Run (the session loop: until the source ends or a limit), and
// Finish (the last grasp's model out repaired, the recording closed).
//
// Bus input is data, never control: a session description the bus
// subscriber rejects (it does not decode, its claw name is not a plain
// name, its values are beyond the config file's limits), or whose claw
// cannot be built, is counted by reason in the status and told once per
// reason (on_notice); the session keeps its claw and config. Every
// description's claw is built and compared with the claw in use on a
// thread of its own (SessionClawChecker), never on the bus's or the
// status's: one that differs is told once per distinct claw.
//
// Threads: the bus's receive thread calls OnDepth / OnGripperState (so may
// anyone; they never wait for fusion, repair or the disk); Run and the rest
// from one thread. The status goes out from Run's thread.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <atomic>
#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "graspfill/io/messages.hpp"
#include "graspfill/repair/repairer.hpp"
#include "module/grasp_module.hpp"
#include "module/repair_stage.hpp"
#include "module/sample_window.hpp"
#include "module/session_claw_checker.hpp"
#include "module/session_loop.hpp"
#include "sinks/lcm_publisher.hpp"
#include "sinks/session_recorder.hpp"
#include "sources/frame_source.hpp"
#include "sources/lcm_bus_subscriber.hpp"
#include "sources/session_overrides.hpp"

namespace graspfill::rt {

struct LiveSessionConfig {
  /// LCM URL for everything ("" = LCM's default); channel names.
  io::ChannelNames channels;
  std::string lcm_url;
  /// Subscribe to depth_image_t on the bus (else depth comes from Run's
  /// source).
  bool depth_from_bus{false};
  /// The bus's hand-eye, intrinsics (of its depth images) and clock offset
  /// over the session descriptions' (a rig config's).
  SourceOverrides overrides;
  /// Depth images from the bus with more pixels are dropped (counted as
  /// bad_size) before their decoded size is allocated (a rig config's
  /// camera.max_depth_pixels).
  int64_t max_depth_pixels{io::kDefaultMaxDepthPixels};
  GraspModuleConfig module;
  /// Repair each cloud before it is published (config for clouds in G).
  bool repair{true};
  repair::RepairConfig repair_config;
  /// Incremental updates between full repairs (repair_stage.hpp).
  RepairStageOptions repair_options;
  /// Repair with what the camera saw (the grasp's visibility record).
  bool repair_evidence{true};
  /// Record what the session received (path empty: no recording).
  SessionRecorder::Config record;
  /// How a session description's claw is built (the CLI: MakeSessionClaw
  /// with the local mesh root) and whether two claws are the same
  /// (SameClaw); both run on the claw checker's thread. Without
  /// build_session_claw, descriptions' claws are neither built nor
  /// compared (and WaitForFirstEvent gives none).
  SessionClawChecker::Build build_session_claw;
  SessionClawChecker::Same same_claw;
  /// A description's claw that is not the claw in use, once per distinct
  /// claw (the claw checker's thread).
  std::function<void(const io::SessionDescription&)> on_other_claw;
  /// One line about bus input rejected (the first rejected session
  /// description of each reason), or about the bus: the first model too
  /// large for a default subscriber's receive buffer (any thread).
  /// Default: printed on stderr.
  std::function<void(const std::string&)> on_notice;
  /// Stop rules; on_tick is the session's (the status).
  SessionLoopLimits limits;
  /// This many depth frames in a row not fused: the status says "stalled".
  int stall_after_frames{30};
  /// > 0: at construction, ReserveHeap(heap_reserve_mb) (process_memory.hpp:
  /// the first grasp's new memory then faults in before the frames come,
  /// not on the frame path). 0 (the default for a host process): the heap
  /// stays as the host set it, since the settings are process-wide.
  /// `graspfill live` reserves 256.
  int heap_reserve_mb{0};
};

/// What the session did, for the summary line.
struct LiveSessionSummary {
  GraspModuleStatus module;
  std::optional<RepairStageStatus> repair;
  int64_t states_received{0};
  int64_t source_errors{0};  ///< the FrameSource's kBadFrame events
  size_t final_points{0};    ///< points of the last cloud published
  int64_t records_written{0};
  int64_t records_dropped{0};
  /// Why the recording stopped early (a full disk), "" if it did not; the
  /// log keeps the records written.
  std::string record_failure;
  io::ModuleStatus status;  ///< the last status published
  /// Arrival of each published cloud's newest frame -> its publication [ms]
  /// (the last 4096 clouds).
  Percentiles latency_ms;
  int64_t clouds_published{0};
};

class LiveSession : private EventSink {
 public:
  /// Opens the bus (throws std::runtime_error if LCM cannot start) and
  /// holds what it receives until Begin.
  explicit LiveSession(const LiveSessionConfig& config);
  ~LiveSession() override;
  LiveSession(const LiveSession&) = delete;
  LiveSession& operator=(const LiveSession&) = delete;

  /// Waits until the first session description whose claw was built, or
  /// a depth frame with no description's claw still being built (or a
  /// limit); returns that description with its claw, if any. Descriptions
  /// rejected on the way are counted and skipped.
  std::optional<DescribedClaw> WaitForFirstEvent();
  /// Waits until no session description's claw waits or is being built
  /// (or `timeout`); true if none. For tests: the verdicts are then out.
  bool WaitSessionChecks(std::chrono::milliseconds timeout) const;

  /// Starts fusing with `claw`; `description` heads the recording.
  /// `pipeline`, when given, replaces the session config's module.pipeline:
  /// what is known only now, e.g. the box and voxel of the session
  /// description the claw came from. Throws on a bad config or an output
  /// that cannot be written.
  void Begin(claw::ClawModel claw, const io::SessionDescription& description,
             const std::optional<PipelineConfig>& pipeline = std::nullopt);

  /// Runs the session loop on `source` (null: depth comes from the bus)
  /// until it ends or a limit stops it; `on_tick` runs on each status tick
  /// (the CLI's late-session warning). Then finishes (see the file comment).
  LiveSessionSummary Run(FrameSource* source, std::function<void()> on_tick = {});

  /// The status as published now (Run's thread).
  io::ModuleStatus Status() const;

  /// Event entry points (any thread; the bus's receive thread).
  void OnDepth(const DepthFrame& frame);
  void OnGripperState(const GripperState& state);

  /// The publisher, for callers that also subscribe on its provider
  /// (memq:// in tests).
  LcmPublisher& publisher() { return publisher_; }
  /// The bus subscriber, for tests and fuzzers that feed its handlers.
  LcmBusSubscriber& subscriber() { return *subscriber_; }

 private:
  bool OnEvent(const SourceEvent& event) override;
  bool OnBadEvent(const SourceEvent& event) override;
  void PublishCloud(const ObjectCloud& cloud);
  void PublishStatus();
  /// on_notice(text), the first time for `reason` only.
  void NoticeOnce(io::MessageError reason, const std::string& text);

  static constexpr size_t kMaxEarlyStates = 64;  // as the module's state queue
  static constexpr size_t kMaxEarlyFrames = 4;   // as the module's frame queue

  LiveSessionConfig config_;
  LcmPublisher publisher_;
  std::mutex publisher_mutex_;  // clouds from the repair thread, status from Run's
  std::unique_ptr<RepairStage> repair_stage_;
  std::unique_ptr<SessionRecorder> recorder_;
  // After the stage and recorder (destroyed before them: nothing is handed
  // to a stage that is gone); before the subscriber, which feeds it.
  std::unique_ptr<GraspModule> module_;
  std::unique_ptr<SessionLoop> loop_;  // made by Begin
  std::function<void()> on_tick_;      // Run's caller's, on the loop's thread

  mutable std::mutex intake_mutex_;  // guards the three below
  bool begun_{false};
  std::deque<GripperState> early_states_;
  std::deque<DepthFrame> early_frames_;

  std::atomic<int64_t> source_errors_{0};
  std::atomic<int64_t> claws_unloadable_{0};  // session descriptions, by the checker
  std::array<std::atomic<bool>, io::BadMessageCounts::kNumReasons> noticed_{};
  // Before the subscriber, which feeds it; stopped before the members its
  // callbacks touch are gone (the destructor).
  std::unique_ptr<SessionClawChecker> claw_checker_;
  mutable std::mutex latency_mutex_;  // the two below: the publishing thread's
  SampleWindow latency_ms_;
  int64_t clouds_published_{0};
  std::atomic<size_t> last_points_out_{0};
  io::ModuleStatus last_status_;
  std::unique_ptr<LcmBusSubscriber> subscriber_;  // last: its thread calls the above
};

}  // namespace graspfill::rt
