// SPDX-License-Identifier: BSD-3-Clause
#include "live_options.hpp"

#include <cmath>

#include "camera_options.hpp"
#include "channel_options.hpp"
#include "claw_option.hpp"
#include "data_paths.hpp"
#include "module/cloud_repair.hpp"
#include "number_parsing.hpp"
#include "sources/openni2_source.hpp"
#include "threads_option.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {
namespace {

constexpr double kMaxSeconds = 7 * 24 * 3600.0;  // a week

// The rig config's camera, hand-eye, clock offset, claw, box, TSDF, repair,
// channels and rates.
void ApplyRig(const rt::RigConfig& c, LiveOptions* o) {
  rt::LiveSessionConfig& session_config = o->session;
  rt::GraspModuleConfig& module_config = session_config.module;
  rt::CameraSource::Config& camera = o->camera;
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
  if (!c.claw.spec.empty()) o->claw_spec = c.claw.spec;
  o->mesh_root = c.claw.mesh_root;
  rt::ApplyToPipeline(c, &module_config.pipeline);
  o->voxel_given = c.tsdf.voxel_m.has_value();
  o->workspace_given = c.workspace.has_value();
  o->sdf_trunc_voxels = c.tsdf.sdf_trunc_voxels;
  session_config.repair = c.repair.enabled;
  session_config.repair_evidence = c.repair.use_evidence;
  session_config.repair_options.incremental = c.repair.incremental;
  rt::ApplyToRepair(c, &o->repair);
  session_config.channels = rt::ToChannelNames(c.channels);
  module_config.extract_every_n_frames = c.rates.publish_every_n_frames;
  session_config.limits.tick_ms = static_cast<int>(std::lround(c.rates.status_period_s * 1000.0));
}

}  // namespace

const char* const kLiveUsage =
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
    "  --depth-scale S       the sensor's depth is S (0.8..1.25) times the true one: divided\n"
    "                        by it from the first frame (rig config camera.depth_scale)\n"
    "  --no-depth-calibration report the depth's scale error the claw shows, but do not\n"
    "                        divide the depth by it (default: divided by it once confident)\n"
    "  --track-object        follow the object slipping in the grasp (frame-to-model)\n"
    "  --record LOG          write what the session receives (session description, depth,\n"
    "                        gripper states) as an LCM log that `graspfill replay` and\n"
    "                        lcm-logplayer play\n"
    "  --force               overwrite the --record LOG if it exists (a regular file only)\n"
    "  --duration-s S        stop after S seconds (default: until Ctrl-C or end of .oni)\n"
    "  --num-threads N       OpenMP threads of each fusion and repair call, 0..1024 (default 1;\n"
    "                        0: OpenMP's own count, a thread per core)\n"
    "  --heap-reserve-mb N   ready the heap for the frame path at start: one arena, nothing\n"
    "                        returned to the system, N MB touched ahead so that the first\n"
    "                        grasp's new memory does not fault in on the frame path\n"
    "                        (default 256; 0: the allocator's defaults), 0..65536\n"
    "  --depth-channel C / --gripper-channel C / --cloud-channel C / --status-channel C /\n"
    "  --session-channel C   channel names: 1..63 of A-Z a-z 0-9 _ - /, each its own\n"
    "example: graspfill live --depth-from-lcm --claw robotiq_3f --claw-mesh-root meshes/ --record s.lcmlog\n";

LiveOptions ParseLiveOptions(const Args& args, const std::optional<rt::RigConfig>& rig) {
  LiveOptions o;
  o.session.heap_reserve_mb = kLiveHeapReserveMb;
  if (rig) ApplyRig(*rig, &o);
  rt::CameraSource::Config& camera = o.camera;
  rt::LiveSessionConfig& session_config = o.session;
  rt::GraspModuleConfig& module_config = session_config.module;
  io::ChannelNames& channels = session_config.channels;
  repair::RepairConfig& repair_config = o.repair;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const bool has_value = i + 1 < args.size();
    if (a == "--help" || a == "-h") {
      o.help = true;
      return o;
    } else if (a == "--config" && has_value)
      ++i;  // read above
    else if (a == "--device" && has_value)
      camera.device.uri = args[++i];
    else if (ParseCameraOption(args, &i, &camera)) {
    } else if (a == "--depth-from-lcm")
      o.depth_from_lcm = true;
    else if (a == "--idle-exit-s" && has_value) {
      session_config.limits.idle_exit_s = ParseDouble(a, args[++i], 0.0, kMaxSeconds, "s");
    } else if (a == "--depth-channel" && has_value)
      channels.depth = args[++i];
    else if (a == "--lcm-url" && has_value)
      session_config.lcm_url = args[++i];
    else if (a == "--claw" && has_value)
      o.claw_spec = args[++i];
    else if (a == "--claw-mesh-root" && has_value)
      o.mesh_root = args[++i];
    else if (a == "--publish-every" && has_value) {
      module_config.extract_every_n_frames = ParseInteger<int>(a, args[++i], 0, 100000);
    } else if (a == "--no-repair")
      session_config.repair = false;
    else if (a == "--no-incremental")
      session_config.repair_options.incremental = false;
    else if (a == "--no-refine")
      module_config.pipeline.refine.enabled = false;
    else if (a == "--refine")
      module_config.pipeline.refine.enabled = true;
    else if (a == "--no-depth-calibration")
      module_config.pipeline.refine.apply_depth_scale = false;
    else if (a == "--track-object")
      module_config.pipeline.track_object.enabled = true;
    else if (a == "--depth-scale" && has_value) {
      module_config.pipeline.refine.known_depth_scale =
          ParseDouble(a, args[++i], refine::kMinDepthScale, refine::kMaxDepthScale, "");
    } else if (a == "--num-threads" && has_value) {
      module_config.pipeline.num_threads = repair_config.num_threads = ParseNumThreads(args[++i]);
    } else if (a == "--repair-mode" && has_value) {
      const std::string mode = args[++i];
      if (mode == "paper")
        repair_config.mode = repair::RepairMode::kPaper;
      else if (mode == "best")
        repair_config.mode = repair::RepairMode::kBest;
      else
        throw UsageError("--repair-mode must be paper or best, not '" + mode + "'");
    } else if (a == "--record" && has_value)
      session_config.record.path = args[++i];
    else if (a == "--force")
      o.force = true;
    else if (a == "--heap-reserve-mb" && has_value) {
      session_config.heap_reserve_mb = ParseInteger<int>(a, args[++i], 0, 65536);
    } else if (a == "--duration-s" && has_value) {
      session_config.limits.duration_s = ParseDouble(a, args[++i], 0.0, kMaxSeconds, "s");
    } else if (a == "--gripper-channel" && has_value)
      channels.gripper_state = args[++i];
    else if (a == "--cloud-channel" && has_value)
      channels.object_cloud = args[++i];
    else if (a == "--status-channel" && has_value)
      channels.status = args[++i];
    else if (a == "--session-channel" && has_value)
      channels.session = args[++i];
    else
      throw BadOption(a, std::string(kLiveUsage) + kCameraUsage);
  }
  CheckChannelOptions(channels);  // the config's and the flags'
  if (o.claw_spec) o.claw_spec = ResolveClawSpec(*o.claw_spec, InstalledClawsDir());
  return o;
}

}  // namespace graspfill::cli
