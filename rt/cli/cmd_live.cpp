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
// file picks the claw and wires the camera to it; the flags are parsed in
// live_options.cpp and the summary told by live_report.cpp.
#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "camera_options.hpp"
#include "claw_option.hpp"
#include "commands.hpp"
#include "config_option.hpp"
#include "error_text.hpp"
#include "graspfill/io/output_path.hpp"
#include "live_options.hpp"
#include "live_report.hpp"
#include "module/cloud_repair.hpp"
#include "module/live_session.hpp"
#include "number_parsing.hpp"

namespace graspfill::cli {
namespace {

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

// The claw the module is made with, and what heads the recording.
struct LiveClaw {
  claw::ClawModel model = claw::ClawModel::ThreeFinger();
  std::string label = "three-finger";
  io::SessionDescription description;
  bool from_session{false};  ///< the bus's or the gripper log's session description
};

// --claw if given; else, with depth from the bus, the session description
// (the first whose claw could be built) or the first depth frame, whichever
// comes first; with OpenNI2 depth, a gripper log alongside may have one.
// A description's box and voxel go into *pipeline unless the config fixed
// them. Prints which claw and why; nullopt (told on stderr): a description
// beyond the config file's limits.
std::optional<LiveClaw> PickClaw(const Args& args, const LiveOptions& o, const std::string& config_path,
                                 rt::LiveSession& live, const rt::CameraSource* camera_source,
                                 PipelineConfig* pipeline) {
  std::optional<rt::DescribedClaw> session;
  if (!o.claw_spec && o.depth_from_lcm) session = live.WaitForFirstEvent();
  if (!o.claw_spec && camera_source && camera_source->session()) {
    const io::SessionDescription& logged = *camera_source->session();
    session = rt::DescribedClaw{logged, MakeSessionClaw(logged, o.mesh_root)};
  }
  LiveClaw claw;
  if (o.claw_spec) {
    claw.model = MakeClaw(*o.claw_spec, o.mesh_root);
    claw.label = *o.claw_spec;
    claw.description = DescribeClaw(*o.claw_spec, o.mesh_root, claw.model);
    std::printf("live: claw %s (from the %s)\n", claw.label.c_str(),
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
      return std::nullopt;
    }
    claw.model = session->claw;
    claw.label = SessionClawLabel(s);
    claw.description = s;
    claw.from_session = true;
    if (s.workspace_G && !o.workspace_given) {
      pipeline->workspace.min_G = s.workspace_G->min();
      pipeline->workspace.max_G = s.workspace_G->max();
    }
    if (s.voxel_m > 0.0 && !o.voxel_given) {
      pipeline->tsdf.voxel_m = s.voxel_m;
      pipeline->tsdf.sdf_trunc_m = o.sdf_trunc_voxels * s.voxel_m;
    }
    std::printf("live: claw %s (from the session description on %s)\n", claw.label.c_str(),
                o.session.channels.session.c_str());
  } else {
    claw.description = DescribeClaw("three-finger", "", claw.model);
    std::printf("live: claw three-finger (default%s)\n",
                o.depth_from_lcm ? ": no session description before the first depth frame" : "");
  }
  std::fflush(stdout);
  // The recording's description tells a replay the box and voxel in use.
  claw.description.workspace_G = Eigen::AlignedBox3d(pipeline->workspace.min_G, pipeline->workspace.max_G);
  claw.description.voxel_m = pipeline->tsdf.voxel_m;
  return claw;
}

// Session descriptions other than the one the module was made with: a
// claw that differs from the one in use is warned about, once per claw
// (on the claw checker's thread; the status is never held up by it).
std::function<void(const io::SessionDescription&)> OtherClawWarning(const LiveOptions& o,
                                                                    const LiveClaw& claw) {
  return [claw_spec = o.claw_spec, claw_label = claw.label, session_channel = o.session.channels.session,
          from_session = claw.from_session](const io::SessionDescription& received) {
    if (claw_spec) {
      std::fprintf(stderr,
                   "graspfill live: warning: --claw %s differs from the claw of the "
                   "session description on %s (%s); using %s\n",
                   claw_spec->c_str(), session_channel.c_str(), SessionClawLabel(received).c_str(),
                   claw_spec->c_str());
    } else if (from_session) {
      std::fprintf(stderr,
                   "graspfill live: warning: a later session description on %s names "
                   "another claw (%s); it is ignored, using %s\n",
                   session_channel.c_str(), SessionClawLabel(received).c_str(), claw_label.c_str());
    } else {
      std::fprintf(stderr,
                   "graspfill live: warning: the session description on %s came after "
                   "the first depth frame; its claw %s is ignored, using %s\n",
                   session_channel.c_str(), SessionClawLabel(received).c_str(), claw_label.c_str());
    }
  };
}

}  // namespace

int RunLive(const Args& args) {
  LiveOptions o;
  std::string config_path;
  try {
    std::optional<rt::RigConfig> rig;
    try {
      rig = LoadConfigOption(args, &config_path);
    } catch (const rt::ConfigError& e) {
      std::fprintf(stderr, "graspfill live: --config: %s\n", e.what());
      return 2;
    }
    o = ParseLiveOptions(args, rig);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "graspfill live: %s\n%s", e.what(), kLiveUsage);
    return 2;
  }
  if (o.help) {
    std::fputs(kLiveUsage, stdout);
    std::fputs(kCameraUsage, stdout);
    return 0;
  }
  rt::LiveSessionConfig& session_config = o.session;
  session_config.depth_from_bus = o.depth_from_lcm;
  session_config.repair_config = rt::GripperFrameRepairConfig(o.repair);
  session_config.record.overwrite = o.force;
  session_config.limits.interrupted = &g_interrupted;
  if (!session_config.record.path.empty()) {
    try {
      io::CheckOutputFile(session_config.record.path, o.force);  // before the session starts
    } catch (const std::exception& e) {
      std::fprintf(stderr, "graspfill live: --record: %s\n", ErrorText(e).c_str());
      return 1;
    }
  }
  o.camera.channels = session_config.channels;
  std::unique_ptr<rt::CameraSource> camera_source;
  if (!o.depth_from_lcm) {
    try {
      camera_source = std::make_unique<rt::CameraSource>(o.camera);
    } catch (const std::exception& e) {
      // Most often no camera is plugged in: say how to run without one.
      std::fprintf(stderr,
                   "graspfill live: %s\n"
                   "  without a camera, take depth from LCM: graspfill live --depth-from-lcm, with a\n"
                   "  publisher of depth_image_t on %s (e.g. lcm-logplayer REC.lcmlog), or replay a\n"
                   "  recording into OpenNI2: --device graspfill-replay:REC.lcmlog\n",
                   ErrorText(e).c_str(), session_config.channels.depth.c_str());
      return 1;
    }
  }
  // Session descriptions' claws: built from their text, meshes only under
  // the local mesh root, on the session's claw thread; one that is not the
  // claw in use is warned about once (the warning set once it is known).
  session_config.build_session_claw = [mesh_root = o.mesh_root](const io::SessionDescription& s) {
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
  if (camera_source) {
    GateFramesOnRoom(camera_source.get(), live, session_config.module.frame_queue_capacity);
  }
  std::signal(SIGINT, [](int) { g_interrupted = true; });
  std::signal(SIGTERM, [](int) { g_interrupted = true; });
  std::signal(SIGHUP, [](int) { g_interrupted = true; });  // a closed terminal: end cleanly

  PipelineConfig pipeline = session_config.module.pipeline;
  const std::optional<LiveClaw> claw = PickClaw(args, o, config_path, live, camera_source.get(), &pipeline);
  if (!claw) return 1;
  *other_claw_warning = OtherClawWarning(o, *claw);
  live.Begin(claw->model, claw->description, pipeline);

  rt::LiveSessionSummary summary;
  try {
    summary = live.Run(camera_source.get());
  } catch (const std::exception& e) {  // the recording could not be completed
    std::fprintf(stderr, "graspfill live: %s\n", ErrorText(e).c_str());
    return 1;
  }
  return PrintLiveSummary(summary, session_config.channels, session_config.record.path);
}

}  // namespace graspfill::cli
