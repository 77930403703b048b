// SPDX-License-Identifier: BSD-3-Clause
// graspfill live: the grasp-and-model session. Depth from an OpenNI2 device
// (or an .oni recording, or depth_image_t on the LCM bus), gripper states
// from the robot over LCM, fusion on the module's worker thread, then the
// hole repair (claw holes and the unseen top, unless --no-repair) on a
// repair stage's thread of its own, and the object cloud published over LCM.
//
// A full repair takes ~60-1,000 ms, a depth frame must be fused within
// ~33 ms: the fusion worker only hands each extracted cloud to the repair
// stage's one-slot mailbox and goes on. The stage repairs a grasp's first
// cloud in full and updates that repair for the next ones (milliseconds),
// while full repairs run behind at a lower priority when the model changed
// enough (rt/module/repair_stage.hpp; --no-incremental: every cloud in
// full). When clouds come faster than the stage, the one waiting is replaced
// by the newer (counted as superseded), so the planner always gets the
// freshest model. The published cloud is as `graspfill replay` writes it:
// fused points first, the repair's after, with its holes and "repair_" and
// "latency_" timings.
//
// The claw: --claw if given. Otherwise, with --depth-from-lcm, the claw of
// the session description (session_description_t on GRASPFILL_SESSION) that
// comes before the first depth frame (as lcm-logplayer plays a recording
// graspfill wrote), with its workspace box and voxel size: the module starts
// once it has one, or once the first depth frame came without one (then
// the three-finger default). Every later session description whose claw is
// not the one in use is warned about, once per claw. With OpenNI2 depth the
// bus's session description is not waited for (the claw is --claw or the
// default). Every session description's hand-eye T_C_B and intrinsics
// override apply to the gripper states and depth images received after it.
//
// Bus input is data, never control (rt/module/live_session.hpp): a session
// description that is bad (its claw name a path, values beyond the config
// file's limits) or whose claw cannot be built is rejected, counted in the
// status and told once per reason; live goes on with the claw it has (or
// the default, or waits for a better one). A description's claw is built
// from its text in memory, its meshes read only under the local
// --claw-mesh-root (claw_option.hpp's MakeSessionClaw).
//
// A rig config (--config FILE, rt/config/rig_config.hpp) sets the camera,
// hand-eye, clock offset, claw, box, TSDF, repair, channels and rates; it
// goes over the session descriptions, and the flags over it.
//
// The session itself is rt::LiveSession (rt/module/live_session.hpp): this
// file parses the flags, picks the claw and wires the camera to it.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "camera_options.hpp"
#include "channel_options.hpp"
#include "claw_option.hpp"
#include "commands.hpp"
#include "config_option.hpp"
#include "data_paths.hpp"
#include "error_text.hpp"
#include "number_parsing.hpp"
#include "unknown_option.hpp"
#include "graspfill/io/output_path.hpp"
#include "graspfill/repair/repairer.hpp"
#include "module/cloud_repair.hpp"
#include "module/live_session.hpp"
#include "sources/openni2_source.hpp"

namespace graspfill::cli {
namespace {

constexpr const char* kUsage =
    "usage: graspfill live [options]\n"
    "  --config FILE         the rig config (`graspfill config --dump-defaults`): over the\n"
    "                        session descriptions; the flags below over it\n"
    "  --device URI          OpenNI2 device URI or an .oni file (default: any device)\n"
    "  --depth-from-lcm      take depth_image_t from the LCM bus instead of OpenNI2\n"
    "                        (a camera driver on another process, or lcm-logplayer)\n"
    "  --idle-exit-s S       stop when no depth frame came for S seconds after the first\n"
    "  --lcm-url URL         LCM bus for gripper states and the cloud (default: LCM's default)\n"
    "  --claw SPEC           three-finger, parallel, a claw description .json or an\n"
    "                        installed description's name, e.g. robotiq_3f (default:\n"
    "                        with --depth-from-lcm the claw of the session description on\n"
    "                        the bus before the first depth frame, else three-finger)\n"
    "  --claw-mesh-root DIR  where the description's meshes are (a session description's\n"
    "                        claw reads its meshes only under this folder)\n"
    "  --publish-every N     publish the cloud every N fused frames, 0..100000 (default 30;\n"
    "                        0: only at the end of each grasp)\n"
    "  --no-repair           publish the fused cloud as is (no hole repair)\n"
    "  --repair-mode MODE    paper: the repair as published; best (default): graspfill's.\n"
    "                        The repair runs beside fusion; a cloud that comes while one\n"
    "                        is repaired waits, and a newer one replaces it (a grasp's\n"
    "                        final model is never replaced)\n"
    "  --no-incremental      repair every published cloud in full (default: update the\n"
    "                        last full repair, full repairs running behind)\n"
    "  --no-refine           fuse at the logged gripper poses (default: correct each frame's\n"
    "                        pose by registering the claw model to the depth)\n"
    "  --refine              the default; over a config's refine.enabled: false\n"
    "  --track-object        follow the object slipping in the grasp (frame-to-model)\n"
    "  --record LOG          write what the session receives (session description, depth,\n"
    "                        gripper states) as an LCM log that `graspfill replay` and\n"
    "                        lcm-logplayer play\n"
    "  --force               overwrite the --record LOG if it exists (a regular file only)\n"
    "  --duration-s S        stop after S seconds (default: until Ctrl-C or end of .oni)\n"
    "  --heap-reserve-mb N   ready the heap for the frame path at start: one arena, nothing\n"
    "                        returned to the system, N MB touched ahead so that the first\n"
    "                        grasp's new memory does not fault in on the frame path\n"
    "                        (default 256; 0: the allocator's defaults), 0..65536\n"
    "  --depth-channel C / --gripper-channel C / --cloud-channel C / --status-channel C /\n"
    "  --session-channel C   channel names: 1..63 of A-Z a-z 0-9 _ - /, each its own\n"
    "example: graspfill live --depth-from-lcm --claw robotiq_3f --claw-mesh-root meshes/ --record s.lcmlog\n";

std::atomic<bool> g_interrupted{false};

// What heads the recording when the claw is not the bus's session
// description's: the claw as given (a file claw as `synth` describes it: a
// URDF as its bundle), identity hand-eye, the defaults.
io::SessionDescription DescribeClaw(const std::string& spec, const std::string& mesh_root,
                                    const claw::ClawModel& model) {
  io::SessionDescription session;
  session.software_version = io::SoftwareVersion();
  if (IsBuiltinClaw(spec)) {
    DescribeBuiltinClaw(spec, claw::ProceduralClawConfig{}, &session);
  } else {
    DescribeFileClaw(spec, mesh_root, model, &session);
  }
  return session;
}

}  // namespace

int RunLive(const Args& args) {
  rt::CameraSource::Config camera;  // camera_options.hpp
  rt::LiveSessionConfig session_config;
  session_config.heap_reserve_mb = kLiveHeapReserveMb;
  io::ChannelNames& channels = session_config.channels;
  rt::GraspModuleConfig& module_config = session_config.module;
  std::optional<std::string> claw_spec;
  std::string mesh_root;
  bool depth_from_lcm = false;
  bool force = false;
  repair::RepairConfig repair_config;
  constexpr double kMaxSeconds = 7 * 24 * 3600.0;  // a week
  // What the config fixes over the session description.
  bool voxel_given = false, workspace_given = false;
  double sdf_trunc_voxels = 4.0;
  std::string config_path;
  try {
    std::optional<rt::RigConfig> rig;
    try {
      rig = LoadConfigOption(args, &config_path);
    } catch (const rt::ConfigError& e) {
      std::fprintf(stderr, "graspfill live: --config: %s\n", e.what());
      return 2;
    }
    if (rig) {
      const rt::RigConfig& c = *rig;
      rt::OpenNI2Source::Config& d = camera.device;
      d.uri = c.camera.device;
      d.width = c.camera.width_px;
      d.height = c.camera.height_px;
      d.fps = c.camera.fps;
      d.depth_mode = c.camera.depth_units == "100um" ? rt::OpenNI2Source::DepthMode::k100um
                                                     : rt::OpenNI2Source::DepthMode::k1mm;
      if (c.camera.intrinsics_override) {
        d.intrinsics.fx = c.camera.intrinsics_override->fx_px;
        d.intrinsics.fy = c.camera.intrinsics_override->fy_px;
        d.intrinsics.cx = c.camera.intrinsics_override->cx_px;
        d.intrinsics.cy = c.camera.intrinsics_override->cy_px;
      }
      session_config.overrides = rt::ToSourceOverrides(c);  // for the bus's depth images too
      camera.overrides = session_config.overrides;
      session_config.max_depth_pixels = c.camera.max_depth_pixels;
      if (!c.claw.spec.empty()) claw_spec = c.claw.spec;
      mesh_root = c.claw.mesh_root;
      rt::ApplyToPipeline(c, &module_config.pipeline);
      voxel_given = c.tsdf.voxel_m.has_value();
      workspace_given = c.workspace.has_value();
      sdf_trunc_voxels = c.tsdf.sdf_trunc_voxels;
      session_config.repair = c.repair.enabled;
      session_config.repair_evidence = c.repair.use_evidence;
      session_config.repair_options.incremental = c.repair.incremental;
      rt::ApplyToRepair(c, &repair_config);
      channels = rt::ToChannelNames(c.channels);
      module_config.extract_every_n_frames = c.rates.publish_every_n_frames;
      session_config.limits.tick_ms = static_cast<int>(std::lround(c.rates.status_period_s * 1000.0));
    }
    for (size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      const bool has_value = i + 1 < args.size();
      if (a == "--help" || a == "-h") { std::fputs(kUsage, stdout); std::fputs(kCameraUsage, stdout); return 0; }
      else if (a == "--config" && has_value) ++i;  // read above
      else if (a == "--device" && has_value) camera.device.uri = args[++i];
      else if (ParseCameraOption(args, &i, &camera)) {}
      else if (a == "--depth-from-lcm") depth_from_lcm = true;
      else if (a == "--idle-exit-s" && has_value) {
        session_config.limits.idle_exit_s = ParseDouble(a, args[++i], 0.0, kMaxSeconds, "s");
      }
      else if (a == "--depth-channel" && has_value) channels.depth = args[++i];
      else if (a == "--lcm-url" && has_value) session_config.lcm_url = args[++i];
      else if (a == "--claw" && has_value) claw_spec = args[++i];
      else if (a == "--claw-mesh-root" && has_value) mesh_root = args[++i];
      else if (a == "--publish-every" && has_value) {
        module_config.extract_every_n_frames = ParseInteger<int>(a, args[++i], 0, 100000);
      }
      else if (a == "--no-repair") session_config.repair = false;
      else if (a == "--no-incremental") session_config.repair_options.incremental = false;
      else if (a == "--no-refine") module_config.pipeline.refine.enabled = false;
      else if (a == "--refine") module_config.pipeline.refine.enabled = true;
      else if (a == "--track-object") module_config.pipeline.track_object.enabled = true;
      else if (a == "--repair-mode" && has_value) {
        const std::string mode = args[++i];
        if (mode == "paper") repair_config.mode = repair::RepairMode::kPaper;
        else if (mode == "best") repair_config.mode = repair::RepairMode::kBest;
        else throw UsageError("--repair-mode must be paper or best, not '" + mode + "'");
      }
      else if (a == "--record" && has_value) session_config.record.path = args[++i];
      else if (a == "--force") force = true;
      else if (a == "--heap-reserve-mb" && has_value) {
        session_config.heap_reserve_mb = ParseInteger<int>(a, args[++i], 0, 65536);
      }
      else if (a == "--duration-s" && has_value) {
        session_config.limits.duration_s = ParseDouble(a, args[++i], 0.0, kMaxSeconds, "s");
      }
      else if (a == "--gripper-channel" && has_value) channels.gripper_state = args[++i];
      else if (a == "--cloud-channel" && has_value) channels.object_cloud = args[++i];
      else if (a == "--status-channel" && has_value) channels.status = args[++i];
      else if (a == "--session-channel" && has_value) channels.session = args[++i];
      else throw BadOption(a, std::string(kUsage) + kCameraUsage);
    }
    CheckChannelOptions(channels);  // the config's and the flags'
    if (claw_spec) claw_spec = ResolveClawSpec(*claw_spec, InstalledClawsDir());
  } catch (const UsageError& e) {
    std::fprintf(stderr, "graspfill live: %s\n%s", e.what(), kUsage);
    return 2;
  }
  session_config.depth_from_bus = depth_from_lcm;
  session_config.repair_config = rt::GripperFrameRepairConfig(repair_config);
  session_config.record.overwrite = force;
  session_config.limits.interrupted = &g_interrupted;
  if (!session_config.record.path.empty()) {
    try {
      io::CheckOutputFile(session_config.record.path, force);  // before the session starts
    } catch (const std::exception& e) {
      std::fprintf(stderr, "graspfill live: --record: %s\n", ErrorText(e).c_str());
      return 1;
    }
  }
  camera.channels = channels;
  std::unique_ptr<rt::CameraSource> camera_source;
  if (!depth_from_lcm) {
    try {
      camera_source = std::make_unique<rt::CameraSource>(camera);
    } catch (const std::exception& e) {
      // Most often no camera is plugged in: say how to run without one.
      std::fprintf(stderr,
                   "graspfill live: %s\n"
                   "  without a camera, take depth from LCM: graspfill live --depth-from-lcm, with a\n"
                   "  publisher of depth_image_t on %s (e.g. lcm-logplayer REC.lcmlog), or replay a\n"
                   "  recording into OpenNI2: --device graspfill-replay:REC.lcmlog\n",
                   ErrorText(e).c_str(), channels.depth.c_str());
      return 1;
    }
  }
  // Session descriptions' claws: built from their text, meshes only under
  // the local mesh root, on the session's claw thread; one that is not the
  // claw in use is warned about once (the text set below, once it is known).
  session_config.build_session_claw = [mesh_root](const io::SessionDescription& s) {
    return MakeSessionClaw(s, mesh_root);
  };
  session_config.same_claw = SameClaw;
  auto other_claw_warning = std::make_shared<std::function<void(const io::SessionDescription&)>>();
  session_config.on_other_claw = [other_claw_warning](const io::SessionDescription& s) {
    if (*other_claw_warning) (*other_claw_warning)(s);
  };
  session_config.on_notice = [](const std::string& text) {
    std::fprintf(stderr, "graspfill live: %s\n", text.c_str());
  };
  rt::LiveSession live(session_config);
  if (camera_source) GateFramesOnRoom(camera_source.get(), live, module_config.frame_queue_capacity);
  std::signal(SIGINT, [](int) { g_interrupted = true; });
  std::signal(SIGTERM, [](int) { g_interrupted = true; });
  std::signal(SIGHUP, [](int) { g_interrupted = true; });  // a closed terminal: end cleanly

  // Without --claw, depth from the bus: the session description (the first
  // whose claw could be built) or the first depth frame, whichever comes
  // first. With OpenNI2 depth, a gripper log alongside may have one.
  std::optional<rt::DescribedClaw> session;  // the one the module is made with
  if (!claw_spec && depth_from_lcm) session = live.WaitForFirstEvent();
  if (!claw_spec && camera_source && camera_source->session()) {
    const io::SessionDescription& logged = *camera_source->session();
    session = rt::DescribedClaw{logged, MakeSessionClaw(logged, mesh_root)};
  }
  claw::ClawModel claw_model = claw::ClawModel::ThreeFinger();
  std::string claw_label = "three-finger";
  io::SessionDescription description;  // heads the recording
  if (claw_spec) {
    claw_model = MakeClaw(*claw_spec, mesh_root);
    claw_label = *claw_spec;
    description = DescribeClaw(*claw_spec, mesh_root, claw_model);
    std::printf("live: claw %s (from the %s)\n", claw_label.c_str(),
                config_path.empty() || std::find(args.begin(), args.end(), "--claw") != args.end()
                    ? "command line"
                    : ("config file " + config_path).c_str());
  } else if (session) {
    // Its values are within the config file's limits (the bus subscriber
    // rejects others; a log's are checked as replay does).
    const io::SessionDescription& s = session->session;
    std::string why;
    if (!io::SessionWithinLimits(s, &why)) {
      std::fprintf(stderr, "graspfill live: the session description %s\n", why.c_str());
      return 1;
    }
    claw_model = session->claw;
    claw_label = SessionClawLabel(s);
    description = s;
    if (s.workspace_G && !workspace_given) {
      module_config.pipeline.workspace.min_G = s.workspace_G->min();
      module_config.pipeline.workspace.max_G = s.workspace_G->max();
    }
    if (s.voxel_m > 0.0 && !voxel_given) {
      module_config.pipeline.tsdf.voxel_m = s.voxel_m;
      module_config.pipeline.tsdf.sdf_trunc_m = sdf_trunc_voxels * s.voxel_m;
    }
    std::printf("live: claw %s (from the session description on %s)\n", claw_label.c_str(),
                channels.session.c_str());
  } else {
    description = DescribeClaw("three-finger", "", claw_model);
    std::printf("live: claw three-finger (default%s)\n",
                depth_from_lcm ? ": no session description before the first depth frame" : "");
  }
  std::fflush(stdout);
  // The recording's description tells a replay the box and voxel in use.
  description.workspace_G = Eigen::AlignedBox3d(module_config.pipeline.workspace.min_G,
                                                module_config.pipeline.workspace.max_G);
  description.voxel_m = module_config.pipeline.tsdf.voxel_m;
  // Session descriptions other than the one the module was made with: a
  // claw that differs from the one in use is warned about, once per claw
  // (on the claw checker's thread; the status is never held up by it).
  const std::string session_channel = channels.session;
  const bool from_session = session.has_value();
  *other_claw_warning = [claw_spec, claw_label, session_channel,
                         from_session](const io::SessionDescription& received) {
    if (claw_spec) {
      std::fprintf(stderr, "graspfill live: warning: --claw %s differs from the claw of the "
                   "session description on %s (%s); using %s\n", claw_spec->c_str(),
                   session_channel.c_str(), SessionClawLabel(received).c_str(),
                   claw_spec->c_str());
    } else if (from_session) {
      std::fprintf(stderr, "graspfill live: warning: a later session description on %s names "
                   "another claw (%s); it is ignored, using %s\n", session_channel.c_str(),
                   SessionClawLabel(received).c_str(), claw_label.c_str());
    } else {
      std::fprintf(stderr, "graspfill live: warning: the session description on %s came after "
                   "the first depth frame; its claw %s is ignored, using %s\n",
                   session_channel.c_str(), SessionClawLabel(received).c_str(),
                   claw_label.c_str());
    }
  };
  live.Begin(claw_model, description);

  rt::LiveSessionSummary summary;
  try {
    summary = live.Run(camera_source.get());
  } catch (const std::exception& e) {  // the recording could not be completed
    std::fprintf(stderr, "graspfill live: %s\n", ErrorText(e).c_str());
    return 1;
  }
  const rt::GraspModuleStatus& s = summary.module;
  std::printf("live: %lld frames in, %lld fused, %lld dropped; %lld gripper states; "
              "cloud of %zu points published on %s\n",
              static_cast<long long>(s.frames_in),
              static_cast<long long>(s.pipeline.frames_integrated),
              static_cast<long long>(s.frames_dropped),
              static_cast<long long>(summary.states_received), summary.final_points,
              channels.object_cloud.c_str());
  const rt::Percentiles& lat = summary.latency_ms;
  std::printf("latency: %lld clouds published; frame arrival -> published p50 %.1f, p95 %.1f, "
              "p99 %.1f, max %.1f ms\n",
              static_cast<long long>(summary.clouds_published), lat.p50, lat.p95, lat.p99, lat.max);
  const io::ModuleStatus& st = summary.status;
  std::printf("live: skipped %lld (no pose %lld, clock jump %lld, bad %lld, pose refinement %lld, "
              "claw empty %lld); %lld decode errors; %lld clock jumps; %lld grasps completed; "
              "state %s\n",
              static_cast<long long>(st.frames_skipped),
              static_cast<long long>(st.frames_skipped_no_pose),
              static_cast<long long>(st.frames_skipped_clock_jump),
              static_cast<long long>(st.frames_bad),
              static_cast<long long>(st.frames_skipped_refine),
              static_cast<long long>(s.session.frames_released),
              static_cast<long long>(st.decode_errors), static_cast<long long>(st.clock_jumps),
              static_cast<long long>(st.grasps_completed), st.state.c_str());
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
  if (!session_config.record.path.empty()) {
    std::printf("record: %lld events written to %s, %lld dropped%s%s\n",
                static_cast<long long>(summary.records_written),
                session_config.record.path.c_str(),
                static_cast<long long>(summary.records_dropped),
                summary.record_failure.empty() ? "" : "; stopped early: ",
                summary.record_failure.c_str());
  }
  if (summary.repair && summary.repair->submitted == 0) {
    std::printf("repair: no cloud to repair\n");
  } else if (summary.repair) {
    const rt::RepairStageStatus& r = *summary.repair;
    std::printf("repair: %lld clouds submitted, %lld repaired, %lld superseded, %lld failed; "
                "last: %s, %zu -> %zu points in %.1f ms\n",
                static_cast<long long>(r.submitted), static_cast<long long>(r.repaired),
                static_cast<long long>(r.superseded), static_cast<long long>(r.failed),
                r.last_status.c_str(), r.last_points_in, r.last_points_out, r.last_repair_ms);
    std::printf("repair: %lld updates (p50 %.1f, p99 %.1f ms), %lld out as fused before the "
                "grasp's first full repair, %lld full published + %lld behind (p50 %.1f, p99 %.1f ms)\n",
                static_cast<long long>(r.updates), r.update_ms.p50, r.update_ms.p99,
                static_cast<long long>(r.unrepaired),
                static_cast<long long>(r.full_published), static_cast<long long>(r.rebases),
                r.full_ms.p50, r.full_ms.p99);
  } else {
    std::printf("repair: off (--no-repair)\n");
  }
  if (!summary.record_failure.empty()) {
    std::fprintf(stderr, "graspfill live: the recording stopped early: %s (the log keeps the "
                 "%lld events written before)\n", summary.record_failure.c_str(),
                 static_cast<long long>(summary.records_written));
    return 1;
  }
  return 0;
}

}  // namespace graspfill::cli
