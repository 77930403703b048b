// SPDX-License-Identifier: BSD-3-Clause
#include "live_report.hpp"

#include <cmath>
#include <cstdio>

#include "graspfill/core/frame_skip.hpp"

namespace graspfill::cli {

int PrintLiveSummary(const rt::LiveSessionSummary& summary, const io::ChannelNames& channels,
                     const std::string& record_path) {
  const rt::GraspModuleStatus& s = summary.module;
  std::printf(
      "live: %lld frames in, %lld fused, %lld dropped; %lld gripper states; "
      "cloud of %zu points published on %s\n",
      static_cast<long long>(s.frames_in), static_cast<long long>(s.pipeline.frames_integrated),
      static_cast<long long>(s.frames_dropped), static_cast<long long>(summary.states_received),
      summary.final_points, channels.object_cloud.c_str());
  const rt::Percentiles& lat = summary.latency_ms;
  std::printf(
      "latency: %lld clouds published; frame arrival -> published p50 %.1f, p95 %.1f, "
      "p99 %.1f, max %.1f ms\n",
      static_cast<long long>(summary.clouds_published), lat.p50, lat.p95, lat.p99, lat.max);
  const io::ModuleStatus& st = summary.status;
  std::printf(
      "live: skipped %lld (no pose %lld, clock jump %lld, bad %lld, pose refinement %lld, "
      "claw empty %lld); %lld decode errors; %lld clock jumps; %lld grasps completed; "
      "state %s\n",
      static_cast<long long>(st.frames_skipped), static_cast<long long>(st.frames_skipped_no_pose),
      static_cast<long long>(st.frames_skipped_clock_jump), static_cast<long long>(st.frames_bad),
      static_cast<long long>(st.frames_skipped_refine), static_cast<long long>(s.session.frames_released),
      static_cast<long long>(st.decode_errors), static_cast<long long>(st.clock_jumps),
      static_cast<long long>(st.grasps_completed), st.state.c_str());
  const refine::DepthScaleEstimate& scale = s.pipeline.refine.depth_scale;
  if (std::isfinite(scale.stderr_)) {
    // What a rig config's camera.depth_scale can take (docs/imperfect-robots.md).
    std::printf("refine: the depth reads %+.2f +- %.2f%% against the claw's size, over %d frames; %s\n",
                100.0 * (scale.factor - 1.0), 100.0 * scale.stderr_, scale.frames,
                scale.applied != 1.0 ? "divided out" : "not divided out");
  }
  if (st.frames_skipped_by_reason.total() > 0) {
    std::printf("live: frames not fused, by reason: %s\n",
                FrameSkipText(st.frames_skipped_by_reason).c_str());
  }
  if (st.decode_errors > 0) {
    std::string reasons;
    for (size_t i = 1; i < io::BadMessageCounts::kNumReasons; ++i) {
      if (st.bad_messages.by_reason[i] == 0) continue;
      reasons += std::string(reasons.empty() ? "" : ", ") +
                 io::MessageErrorName(static_cast<io::MessageError>(i)) + " " +
                 std::to_string(st.bad_messages.by_reason[i]);
    }
    std::printf("live: decode errors by reason: %s\n", reasons.c_str());
  }
  if (!record_path.empty()) {
    std::printf("record: %lld events written to %s, %lld dropped%s%s\n",
                static_cast<long long>(summary.records_written), record_path.c_str(),
                static_cast<long long>(summary.records_dropped),
                summary.record_failure.empty() ? "" : "; stopped early: ", summary.record_failure.c_str());
  }
  if (summary.repair && summary.repair->submitted == 0) {
    std::printf("repair: no cloud to repair\n");
  } else if (summary.repair) {
    const rt::RepairStageStatus& r = *summary.repair;
    std::printf(
        "repair: %lld clouds submitted, %lld repaired, %lld superseded, %lld failed; "
        "last: %s, %zu -> %zu points in %.1f ms\n",
        static_cast<long long>(r.submitted), static_cast<long long>(r.repaired),
        static_cast<long long>(r.superseded), static_cast<long long>(r.failed), r.last_status.c_str(),
        r.last_points_in, r.last_points_out, r.last_repair_ms);
    std::printf(
        "repair: %lld updates (p50 %.1f, p99 %.1f ms), %lld out as fused before the "
        "grasp's first full repair, %lld full published + %lld behind (p50 %.1f, p99 %.1f ms)\n",
        static_cast<long long>(r.updates), r.update_ms.p50, r.update_ms.p99,
        static_cast<long long>(r.unrepaired), static_cast<long long>(r.full_published),
        static_cast<long long>(r.rebases), r.full_ms.p50, r.full_ms.p99);
  } else {
    std::printf("repair: off (--no-repair)\n");
  }
  if (!summary.record_failure.empty()) {
    std::fprintf(stderr,
                 "graspfill live: the recording stopped early: %s (the log keeps the "
                 "%lld events written before)\n",
                 summary.record_failure.c_str(), static_cast<long long>(summary.records_written));
    return 1;
  }
  return 0;
}

}  // namespace graspfill::cli
