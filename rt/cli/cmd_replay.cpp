// SPDX-License-Identifier: BSD-3-Clause
// graspfill replay LOG -o cloud.ply: the recorded depth log through the same
// Pipeline the live loop uses, then the hole repair (claw holes and the
// unseen top, unless --no-repair), then the object cloud to PLY and LCM.
// The fused points come first, unchanged and in order (provenance
// observed); the repair's points follow (provenance surface / symmetry), and
// its holes and stage timings ride along in the LCM message.
//
// The recording's session description (session_description_t, at its head)
// gives the claw, the hand-eye calibration, the intrinsics override, the
// workspace box and the voxel size; --claw and --voxel-m override it, and a
// --claw that is not the recording's claw is warned about. Without one the
// defaults apply (the three-finger claw). A rig config (--config FILE,
// rt/config/rig_config.hpp) goes over the session description, and the
// command line's flags over both.
//
// The session itself is rt::ReplaySession (rt/module/replay_session.hpp):
// this file parses the flags, picks the claw, writes the preview and the
// collision mesh the session made of the model, and reports
// (replay_report.hpp).
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>

#include "channel_options.hpp"
#include "claw_option.hpp"
#include "commands.hpp"
#include "config_option.hpp"
#include "data_paths.hpp"
#include "error_text.hpp"
#include "graspfill/io/cloud_file.hpp"
#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/io/output_path.hpp"
#include "mesh_option.hpp"
#include "module/replay_session.hpp"
#include "number_parsing.hpp"
#include "preview.hpp"
#include "progress.hpp"
#include "refine_json.hpp"
#include "replay_report.hpp"
#include "threads_option.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {
namespace {

constexpr const char* kReplayUsage =
    "usage: graspfill replay LOG -o CLOUD.{ply,pcd} [options]\n"
    "  --config FILE            the rig config (`graspfill config --dump-defaults`): over the\n"
    "                           recording's session description; the flags below over it\n"
    "  -o, --output PATH        object cloud in the gripper frame (PLY or PCD, by its\n"
    "                           extension): the fused points, then the points the repair\n"
    "                           added (provenance: 0 observed, 1 surface, 2 symmetry)\n"
    "  --mesh-out FILE          also the model's collision mesh for the planner (.ply, .stl\n"
    "                           or .obj), its deviation from the cloud printed (and in\n"
    "                           --json), published on the mesh channel (collision_mesh_t)\n"
    "  --mesh-max-triangles N   the mesh's most triangles (default 5000): decimated,\n"
    "                           watertight, inflated to hold the cloud\n"
    "  --mesh-convex-hull       the cloud's convex hull as the mesh instead\n"
    "  --no-repair              write and publish the fused cloud only\n"
    "  --repair-mode MODE       paper: the repair as published; best (default): graspfill's\n"
    "  --no-evidence            repair from the cloud alone (without what the camera saw)\n"
    "  --json                   print the report as JSON (\"repair\" is null with --no-repair)\n"
    "  --force                  overwrite the output (and the preview) if it exists\n"
    "  --preview DIR            also a picture of the cloud before and after the repair:\n"
    "                           DIR/<CLOUD's stem>.png (see `graspfill view`)\n"
    "  --claw SPEC              three-finger, parallel, a claw description .json or an\n"
    "                           installed description's name, e.g. robotiq_3f (default:\n"
    "                           the recording's claw, from its session description, else\n"
    "                           three-finger); one that differs from the recording's is warned about\n"
    "  --claw-mesh-root DIR     where the description's meshes are (default: beside it)\n"
    "  --lcm-url URL            publish here (default: LCM's default, LCM_DEFAULT_URL or udpm)\n"
    "  --no-publish             do not publish the cloud over LCM\n"
    "  --depth-channel NAME     default GRASPFILL_DEPTH\n"
    "  --gripper-channel NAME   default GRASPFILL_GRIPPER_STATE\n"
    "  --cloud-channel NAME     default GRASPFILL_OBJECT_CLOUD\n"
    "  --session-channel NAME   default GRASPFILL_SESSION\n"
    "  --mesh-channel NAME      default GRASPFILL_COLLISION_MESH\n"
    "                           (names: 1..63 of A-Z a-z 0-9 _ - /, each its own)\n"
    "  --voxel-m V              TSDF voxel size, 0.0005..0.01 m (default: the recording's, else 0.0015)\n"
    "  --skip-bad-frames        skip malformed events instead of failing\n"
    "  --num-threads N          OpenMP threads of the fusion and the repair, 0..1024 (default 1;\n"
    "                           0: OpenMP's own count, a thread per core)\n"
    "  --refine                 correct each frame's gripper pose by registering the claw\n"
    "                           model to the depth (the default)\n"
    "  --no-refine              fuse at the logged gripper poses\n"
    "  --depth-scale S          the recording's depth is S (0.8..1.25) times the true one:\n"
    "                           divided by it from the first frame (rig config\n"
    "                           camera.depth_scale; e.g. what an earlier replay found)\n"
    "  --no-depth-calibration   report the depth's scale error the claw shows (--json\n"
    "                           refine.depth_scale), but do not divide the depth by it\n"
    "                           (default: divided by it once confident)\n"
    "  --track-object           follow the object slipping in the grasp: align each frame's\n"
    "                           object pixels to the model fused so far and fuse it in the\n"
    "                           object's frame as first seen (the cloud's frame; where the\n"
    "                           object is in G now: --json track_object.object_pose)\n"
    "example: graspfill replay replay/default/recording.lcmlog -o model.pcd --mesh-out hull.stl\n";

struct ReplayOptions {
  rt::ReplaySessionConfig session;
  std::string preview_dir;       ///< --preview, "" = none
  std::string mesh_out;          ///< --mesh-out, "" = none
  mesh::PlannerMeshConfig mesh;  ///< the config's collision_mesh, then the flags
  bool mesh_flags{false};        ///< --mesh-max-triangles or --mesh-convex-hull given
  bool json{false};
  std::optional<std::string> claw;        ///< --claw or the config's; none = the recording's
  std::string claw_from{"command line"};  ///< where `claw` came from
  std::string claw_mesh_root;
  std::string config_path;  ///< --config, "" = none
};

// The voxel edge, with the truncation distance at `trunc_voxels` voxels.
void SetVoxel(double voxel_m, double trunc_voxels, PipelineConfig* config) {
  config->tsdf.voxel_m = voxel_m;
  config->tsdf.sdf_trunc_m = trunc_voxels * voxel_m;
}

// The rig config's values, before the flags (which override them).
void ApplyConfig(const rt::RigConfig& c, ReplayOptions* o) {
  rt::ReplaySessionConfig& s = o->session;
  rt::ApplyToPipeline(c, &s.pipeline);
  s.voxel_fixed = c.tsdf.voxel_m.has_value();
  s.workspace_fixed = c.workspace.has_value();
  s.sdf_trunc_voxels = c.tsdf.sdf_trunc_voxels;
  rt::ApplyToRepair(c, &s.repair_config);
  rt::ApplyToCollisionMesh(c, &o->mesh);
  s.repair = c.repair.enabled;
  s.repair_evidence = c.repair.use_evidence;
  s.log.channels = rt::ToChannelNames(c.channels);
  if (!c.claw.spec.empty()) {
    o->claw = c.claw.spec;
    o->claw_from = "config file";
  }
  o->claw_mesh_root = c.claw.mesh_root;
  s.log.overrides = rt::ToSourceOverrides(c);
  s.log.max_depth_pixels = c.camera.max_depth_pixels;
}

// Throws UsageError (printed with the usage text, exit code 2).
void Parse(const Args& args, ReplayOptions* o) {
  rt::ReplaySessionConfig& s = o->session;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](std::string* out) {
      if (i + 1 >= args.size()) throw UsageError(a + " needs a value");
      *out = args[++i];
    };
    std::string v;
    if (a == "--config")
      value(&o->config_path);  // read before (LoadConfigOption)
    else if (a == "-o" || a == "--output")
      value(&s.output_path);
    else if (a == "--preview")
      value(&o->preview_dir);
    else if (a == "--mesh-out")
      value(&o->mesh_out);
    else if (ParseMeshFlag(args, &i, &o->mesh, &o->mesh_flags))
      continue;
    else if (a == "--json")
      o->json = true;
    else if (a == "--force")
      s.overwrite = true;
    else if (a == "--claw") {
      value(&v);
      o->claw = v;
      o->claw_from = "command line";
    } else if (a == "--claw-mesh-root")
      value(&o->claw_mesh_root);
    else if (a == "--lcm-url")
      value(&s.lcm_url);
    else if (a == "--no-publish")
      s.publish = false;
    else if (a == "--skip-bad-frames")
      s.skip_bad_events = true;
    else if (a == "--no-repair")
      s.repair = false;
    else if (a == "--no-evidence")
      s.repair_evidence = false;
    else if (a == "--no-refine")
      s.pipeline.refine.enabled = false;
    else if (a == "--refine")
      s.pipeline.refine.enabled = true;
    else if (a == "--no-depth-calibration")
      s.pipeline.refine.apply_depth_scale = false;
    else if (a == "--track-object")
      s.pipeline.track_object.enabled = true;
    else if (a == "--num-threads") {
      value(&v);
      s.pipeline.num_threads = s.repair_config.num_threads = ParseNumThreads(v);
    } else if (a == "--repair-mode") {
      value(&v);
      if (v == "paper")
        s.repair_config.mode = repair::RepairMode::kPaper;
      else if (v == "best")
        s.repair_config.mode = repair::RepairMode::kBest;
      else
        throw UsageError("--repair-mode must be paper or best, not '" + v + "'");
    } else if (a == "--depth-channel")
      value(&s.log.channels.depth);
    else if (a == "--gripper-channel")
      value(&s.log.channels.gripper_state);
    else if (a == "--cloud-channel")
      value(&s.log.channels.object_cloud);
    else if (a == "--session-channel")
      value(&s.log.channels.session);
    else if (a == "--mesh-channel")
      value(&s.log.channels.collision_mesh);
    else if (a == "--depth-scale") {
      value(&v);
      s.pipeline.refine.known_depth_scale =
          ParseDouble(a, v, refine::kMinDepthScale, refine::kMaxDepthScale, "");
    } else if (a == "--voxel-m") {
      value(&v);
      SetVoxel(ParseDouble(a, v, kMinVoxelM, kMaxVoxelM, "m"), s.sdf_trunc_voxels, &s.pipeline);
      s.voxel_fixed = true;
    } else if (!a.empty() && a[0] == '-') {
      throw BadOption(a, kReplayUsage);
    } else if (s.log.path.empty()) {
      s.log.path = a;
    } else {
      throw UsageError("unexpected argument " + a);
    }
  }
  if (s.log.path.empty() || s.output_path.empty()) {
    throw UsageError("need LOG and -o CLOUD.ply");
  }
  try {
    io::CloudFileFormatOf(s.output_path);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("-o ") + e.what());
  }
  if (o->claw) o->claw = ResolveClawSpec(*o->claw, InstalledClawsDir());
  CheckMeshOutOption(o->mesh_out, s.output_path, o->mesh_flags);
  if (!o->mesh_out.empty()) s.collision_mesh = o->mesh;
  CheckChannelOptions(s.log.channels);  // the config's and the flags'
}

// The claw the replay fuses with (the session's claw chooser): --claw or
// the config's claw.spec over the recording's (warned about when they
// differ), else the recording's, else the three-finger default.
// Throws std::runtime_error on a claw that cannot be built.
claw::ClawModel ChooseClaw(const ReplayOptions& o, const std::optional<io::SessionDescription>& session,
                           ClawUse* use) {
  if (o.claw) {
    claw::ClawModel model = MakeClaw(*o.claw, o.claw_mesh_root);
    use->label = *o.claw;
    use->from = o.claw_from;
    if (session) {
      // The recording's claw as it was; one that cannot be built (a URDF,
      // meshes not here) is compared by name.
      bool same = false;
      try {
        same = SameClaw(model, MakeSessionClaw(*session, o.claw_mesh_root));
      } catch (const std::exception&) {
        same = model.name() == session->claw_name;
      }
      if (!same) {
        const std::string given = o.claw_from == "config file"
                                      ? "the config's claw.spec " + *o.claw + " (" + o.config_path + ")"
                                      : "--claw " + *o.claw;
        std::fprintf(stderr,
                     "graspfill replay: warning: %s differs from the claw this recording "
                     "was made with (%s, from its session description); using %s\n",
                     given.c_str(), SessionClawLabel(*session).c_str(), o.claw->c_str());
      }
    }
    return model;
  }
  if (session) {
    use->label = SessionClawLabel(*session);
    use->from = "session description";
    return MakeSessionClaw(*session, o.claw_mesh_root);
  }
  use->label = "three-finger";
  use->from = "default";
  return claw::ClawModel::ThreeFinger();
}

// Depth frames in the log, for the progress line's total (headers and
// channel names only matter; a log that ends badly is reported later).
int64_t CountDepthFrames(const std::string& path, const std::string& channel) {
  io::LcmLogReader reader(path);
  io::LogEvent event;
  int64_t frames = 0;
  while (reader.Next(&event) == io::LogReadResult::kEvent) frames += event.channel == channel;
  return frames;
}

// The notes of a replay that went on (a late session description, a log
// cut short), in the order the replay met them.
void PrintNotes(const ReplayOptions& o, const rt::ReplayResult& r) {
  if (r.late_sessions > 0) {
    std::fprintf(stderr,
                 "graspfill replay: warning: the session description at utime %lld "
                 "comes after the recording's first one or its first events; its claw, "
                 "workspace box and voxel are ignored\n",
                 static_cast<long long>(r.late_session_utime));
  }
  if (r.partial_event_bytes > 0) {
    // A recording cut short (crash, kill, power cut, full disk): the whole
    // events before its partial last one are the log.
    std::fprintf(stderr,
                 "graspfill replay: note: log '%s' ends in a partial event (%lld bytes "
                 "after its %lld whole events: a recording cut short), skipped\n",
                 o.session.log.path.c_str(), static_cast<long long>(r.partial_event_bytes),
                 static_cast<long long>(r.events_read));
  }
}

// Why the replay failed, on stderr (its exit code is 1).
void PrintFailure(const ReplayOptions& o, const rt::ReplaySession& session, const rt::ReplayResult& r) {
  const rt::ReplaySessionConfig& c = o.session;
  switch (r.end) {
    case rt::ReplayEnd::kDone:
      return;
    case rt::ReplayEnd::kBadEvent:
      std::fprintf(stderr,
                   "graspfill replay: bad event in '%s': %s\n"
                   "(pass --skip-bad-frames to skip such events)\n",
                   c.log.path.c_str(), r.error.c_str());
      return;
    case rt::ReplayEnd::kLogCorrupt:
      std::fprintf(stderr, "graspfill replay: log '%s' is truncated after %lld events (%s)\n",
                   c.log.path.c_str(), static_cast<long long>(r.events_read), r.error.c_str());
      return;
    case rt::ReplayEnd::kNoDepthFrames: {
      std::string seen;
      for (const std::string& ch : r.channels_seen) seen += (seen.empty() ? "" : ", ") + ch;
      std::fprintf(stderr, "graspfill replay: no depth frames on channel '%s' in '%s' (channels: %s)\n",
                   c.log.channels.depth.c_str(), c.log.path.c_str(), seen.empty() ? "none" : seen.c_str());
      return;
    }
    case rt::ReplayEnd::kRefineRejectedEvery:
      std::fprintf(stderr,
                   "graspfill replay: pose refinement rejected every posed frame (%s)\n"
                   "(pass --no-refine to fuse at the logged poses)\n",
                   RefineSummary(*session.pipeline()).c_str());
      return;
    case rt::ReplayEnd::kNoPosedFrames:
      std::fprintf(stderr,
                   "graspfill replay: no depth frame had a gripper pose within %.1f ms "
                   "(%lld frames, %lld gripper states)\n",
                   c.pipeline.max_pose_gap_us / 1000.0, static_cast<long long>(r.stats.frames_in),
                   static_cast<long long>(r.stats.states_in));
      return;
    case rt::ReplayEnd::kDeliveryFailed:
      break;
  }
  const rt::GraspDelivery& g = r.grasps.back();
  if (g.step == rt::DeliveryStep::kRepairFailed) {
    std::fprintf(stderr,
                 "graspfill replay: hole repair failed on the fused cloud (%zu points): %s\n"
                 "(pass --no-repair to write the fused cloud as is)\n",
                 g.fused_points, g.repair_error.c_str());
  } else if (g.model == rt::DeliveredModel::kEarlierGrasp) {
    std::fprintf(stderr, "graspfill replay: grasp %lld: %s\n", static_cast<long long>(g.grasp_id),
                 g.write_error.c_str());
  } else {
    std::fprintf(stderr, "graspfill replay: %s\n", g.write_error.c_str());
  }
}

// Before the log is read: an output that cannot be written (its folder
// missing or read-only, a folder, a link or an existing file without
// --force) is found now, not after the whole replay. False after saying why.
bool CheckOutputs(const ReplayOptions& o) {
  try {
    io::CheckOutputFile(o.session.output_path, o.session.overwrite);
    if (!o.mesh_out.empty()) io::CheckOutputFile(o.mesh_out, o.session.overwrite);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill replay: %s\n", ErrorText(e).c_str());
    return false;
  }
  return o.preview_dir.empty() ||
         PreparePreview(o.preview_dir, o.session.output_path, o.session.overwrite, "replay");
}

// The preview and the collision mesh of the model written (the last
// grasp's), into *report. False after saying why one failed.
bool WritePictureAndMesh(const ReplayOptions& o, const rt::ReplayResult& r, std::string* preview_path,
                         nlohmann::ordered_json* mesh) {
  try {
    if (!o.preview_dir.empty()) {
      *preview_path =
          WritePreview(o.preview_dir, o.session.output_path, r.output_fused ? &*r.output_fused : nullptr,
                       r.output, o.session.overwrite);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill replay: %s\n", ErrorText(e).c_str());
    return false;
  }
  if (o.mesh_out.empty()) return true;
  try {
    if (!r.collision_mesh) throw std::runtime_error(r.mesh_error);
    *mesh = WriteCollisionMesh(o.mesh_out, r.output, *r.collision_mesh, o.mesh, r.mesh_ms,
                               r.mesh_published ? o.session.log.channels.collision_mesh : "",
                               o.session.overwrite);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill replay: collision mesh: %s\n", ErrorText(e).c_str());
    return false;
  }
  return true;
}

}  // namespace

int RunReplay(const Args& args) {
  for (const std::string& a : args) {
    if (a == "--help" || a == "-h") {
      std::fputs(kReplayUsage, stdout);
      return 0;
    }
  }
  ReplayOptions o;
  try {
    if (const std::optional<rt::RigConfig> config = LoadConfigOption(args, &o.config_path)) {
      ApplyConfig(*config, &o);
    }
    Parse(args, &o);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "graspfill replay: %s\n%s", e.what(), kReplayUsage);
    return 2;
  } catch (const rt::ConfigError& e) {
    std::fprintf(stderr, "graspfill replay: --config: %s\n", e.what());
    return 2;
  }
  if (!CheckOutputs(o)) return 1;

  ClawUse claw_use;
  o.session.choose_claw = [&o, &claw_use](const std::optional<io::SessionDescription>& s) {
    return ChooseClaw(o, s, &claw_use);
  };
  o.session.keep_output_fused = !o.preview_dir.empty();
  std::optional<ProgressLine> progress;
  if (ProgressWanted()) {
    o.session.on_progress = [&progress](int64_t frames) { progress->Update(frames); };
  }
  rt::ReplaySession session(o.session);  // throws on a bad file
  if (o.session.on_progress) {
    progress.emplace("replay", "frames", CountDepthFrames(o.session.log.path, o.session.log.channels.depth));
  }
  const rt::ReplayResult result = session.Run();
  progress.reset();  // the line erased before anything else is printed
  PrintNotes(o, result);
  if (!o.json) PrintEarlierGrasps(result);
  if (result.end != rt::ReplayEnd::kDone) {
    PrintFailure(o, session, result);
    return 1;
  }
  std::string preview_path;
  nlohmann::ordered_json mesh;
  if (!WritePictureAndMesh(o, result, &preview_path, &mesh)) return 1;
  const ReplayReport report{o.session,
                            result,
                            *session.pipeline(),
                            claw_use,
                            o.config_path,
                            preview_path,
                            o.mesh_out.empty() ? nullptr : &mesh};
  if (o.json)
    std::printf("%s\n", ReplayReportJson(report).dump(2).c_str());
  else
    PrintReplayReport(report);
  return 0;
}

}  // namespace graspfill::cli
