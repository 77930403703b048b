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
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "channel_options.hpp"
#include "claw_option.hpp"
#include "commands.hpp"
#include "config_option.hpp"
#include "error_text.hpp"
#include "evidence_json.hpp"
#include "mesh_option.hpp"
#include "number_parsing.hpp"
#include "preview.hpp"
#include "progress.hpp"
#include "refine_json.hpp"
#include "track_json.hpp"
#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/io/output_path.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/pipeline/pipeline.hpp"
#include "graspfill/repair/repairer.hpp"
#include "module/cloud_repair.hpp"
#include "module/grasp_sequencer.hpp"
#include "module/sequencer_feed.hpp"
#include "module/session_loop.hpp"
#include "sinks/lcm_publisher.hpp"
#include "sources/lcm_log_source.hpp"
#include "sources/prefetching_source.hpp"

namespace graspfill::cli {
namespace {

constexpr const char* kUsage =
    "usage: graspfill replay LOG -o CLOUD.ply [options]\n"
    "  --config FILE            the rig config (`graspfill config --dump-defaults`): over the\n"
    "                           recording's session description; the flags below over it\n"
    "  -o, --output PATH        object cloud in the gripper frame (PLY): the fused points,\n"
    "                           then the points the repair added (property provenance:\n"
    "                           0 observed, 1 surface, 2 symmetry)\n"
    "  --mesh-out FILE          also the model's closed collision mesh (.ply, .stl or .obj),\n"
    "                           its deviation from the cloud printed (and in --json)\n"
    "  --no-repair              write and publish the fused cloud only\n"
    "  --repair-mode MODE       paper: the repair as published; best (default): graspfill's\n"
    "  --no-evidence            repair from the cloud alone (without what the camera saw)\n"
    "  --json                   print the report as JSON (\"repair\" is null with --no-repair)\n"
    "  --force                  overwrite the output (and the preview) if it exists\n"
    "  --preview DIR            also a picture of the cloud before and after the repair:\n"
    "                           DIR/<CLOUD's stem>.png (see `graspfill view`)\n"
    "  --claw SPEC              three-finger, parallel, or a claw description .json (default:\n"
    "                           the recording's claw, from its session description, else\n"
    "                           three-finger); one that differs from the recording's is warned about\n"
    "  --claw-mesh-root DIR     where the description's meshes are (default: beside it)\n"
    "  --lcm-url URL            publish here (default: LCM's default, LCM_DEFAULT_URL or udpm)\n"
    "  --no-publish             do not publish the cloud over LCM\n"
    "  --depth-channel NAME     default GRASPFILL_DEPTH\n"
    "  --gripper-channel NAME   default GRASPFILL_GRIPPER_STATE\n"
    "  --cloud-channel NAME     default GRASPFILL_OBJECT_CLOUD\n"
    "  --session-channel NAME   default GRASPFILL_SESSION\n"
    "                           (names: 1..63 of A-Z a-z 0-9 _ - /, each its own)\n"
    "  --voxel-m V              TSDF voxel size, 0.0005..0.01 m (default: the recording's, else 0.0015)\n"
    "  --skip-bad-frames        skip malformed events instead of failing\n"
    "  --refine                 correct each frame's gripper pose by registering the claw\n"
    "                           model to the depth (the default)\n"
    "  --no-refine              fuse at the logged gripper poses\n"
    "  --track-object           follow the object slipping in the grasp: align each frame's\n"
    "                           object pixels to the model fused so far and fuse it in the\n"
    "                           object's frame as first seen (the cloud's frame; where the\n"
    "                           object is in G now: --json track_object.object_pose)\n";

struct ReplayOptions {
  std::string log_path;
  std::string output_path;
  std::string preview_dir;  ///< --preview, "" = none
  std::string mesh_out;  ///< --mesh-out, "" = none
  bool json{false};
  bool force{false};
  std::optional<std::string> claw;  ///< --claw or the config's; none = the recording's
  std::string claw_from{"command line"};  ///< where `claw` came from
  std::string claw_mesh_root;
  bool voxel_given{false};      ///< the voxel is the command line's or the config's
  bool workspace_given{false};  ///< the box is the config's
  double sdf_trunc_voxels{4.0};
  std::string config_path;      ///< --config, "" = none
  /// The config's hand-eye, intrinsics override and clock offset (over the
  /// session description's).
  std::optional<Eigen::Isometry3d> T_C_B;
  std::optional<CameraIntrinsics> intrinsics;
  int64_t clock_offset_us{0};
  int64_t max_depth_pixels{io::kDefaultMaxDepthPixels};  ///< the config's camera.max_depth_pixels
  std::string lcm_url;
  bool publish{true};
  bool skip_bad_frames{false};
  bool repair{true};
  bool evidence{true};
  io::ChannelNames channels;
  PipelineConfig pipeline;
  repair::RepairConfig repair_config;
};

// The voxel edge, with the truncation distance at `trunc_voxels` voxels
// (default 4).
void SetVoxel(double voxel_m, double trunc_voxels, PipelineConfig* config) {
  config->tsdf.voxel_m = voxel_m;
  config->tsdf.sdf_trunc_m = trunc_voxels * voxel_m;
}

// The rig config's values, before the flags (which override them).
void ApplyConfig(const rt::RigConfig& c, ReplayOptions* o) {
  rt::ApplyToPipeline(c, &o->pipeline);
  o->voxel_given = c.tsdf.voxel_m.has_value();
  o->workspace_given = c.workspace.has_value();
  o->sdf_trunc_voxels = c.tsdf.sdf_trunc_voxels;
  rt::ApplyToRepair(c, &o->repair_config);
  o->repair = c.repair.enabled;
  o->evidence = c.repair.use_evidence;
  o->channels = rt::ToChannelNames(c.channels);
  if (!c.claw.spec.empty()) {
    o->claw = c.claw.spec;
    o->claw_from = "config file";
  }
  o->claw_mesh_root = c.claw.mesh_root;
  if (c.robot.T_C_B) o->T_C_B = c.robot.T_C_B->ToIsometry();
  o->intrinsics = rt::IntrinsicsOverride(c);
  o->clock_offset_us = rt::ClockOffsetUs(c);
  o->max_depth_pixels = c.camera.max_depth_pixels;
}

// Throws UsageError (printed with the usage text, exit code 2).
bool Parse(const Args& args, ReplayOptions* o) {
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](std::string* out) {
      if (i + 1 >= args.size()) throw UsageError(a + " needs a value");
      *out = args[++i];
    };
    std::string v;
    if (a == "--config") value(&o->config_path);  // read before (LoadConfigOption)
    else if (a == "-o" || a == "--output") value(&o->output_path);
    else if (a == "--preview") value(&o->preview_dir);
    else if (a == "--mesh-out") value(&o->mesh_out);
    else if (a == "--json") o->json = true;
    else if (a == "--force") o->force = true;
    else if (a == "--claw") {
      value(&v);
      o->claw = v;
      o->claw_from = "command line";
    }
    else if (a == "--claw-mesh-root") value(&o->claw_mesh_root);
    else if (a == "--lcm-url") value(&o->lcm_url);
    else if (a == "--no-publish") o->publish = false;
    else if (a == "--skip-bad-frames") o->skip_bad_frames = true;
    else if (a == "--no-repair") o->repair = false;
    else if (a == "--no-evidence") o->evidence = false;
    else if (a == "--no-refine") o->pipeline.refine.enabled = false;
    else if (a == "--refine") o->pipeline.refine.enabled = true;
    else if (a == "--track-object") o->pipeline.track_object.enabled = true;
    else if (a == "--repair-mode") {
      value(&v);
      if (v == "paper") o->repair_config.mode = repair::RepairMode::kPaper;
      else if (v == "best") o->repair_config.mode = repair::RepairMode::kBest;
      else throw UsageError("--repair-mode must be paper or best, not '" + v + "'");
    }
    else if (a == "--depth-channel") value(&o->channels.depth);
    else if (a == "--gripper-channel") value(&o->channels.gripper_state);
    else if (a == "--cloud-channel") value(&o->channels.object_cloud);
    else if (a == "--session-channel") value(&o->channels.session);
    else if (a == "--voxel-m") {
      value(&v);
      SetVoxel(ParseDouble(a, v, kMinVoxelM, kMaxVoxelM, "m"), o->sdf_trunc_voxels, &o->pipeline);
      o->voxel_given = true;
    } else if (!a.empty() && a[0] == '-') {
      throw UsageError("unknown option " + a);
    } else if (o->log_path.empty()) {
      o->log_path = a;
    } else {
      throw UsageError("unexpected argument " + a);
    }
  }
  if (o->log_path.empty() || o->output_path.empty()) {
    throw UsageError("need LOG and -o CLOUD.ply");
  }
  if (!o->mesh_out.empty()) CheckMeshOutOption(o->mesh_out, o->output_path);
  CheckChannelOptions(o->channels);  // the config's and the flags'
  return true;
}

// The claw the replay uses and where it came from.
struct ClawUse {
  std::string label;  ///< how messages name it
  std::string from;   ///< "command line", "config file", "session description" or "default"
};

// Builds the pipeline once the events before the first depth or gripper
// event are known: the claw and config from `session` (the recording's
// first session description, if it has one) unless the command line says
// otherwise. Prints the warning when --claw is not the recording's claw.
// Throws std::runtime_error on a claw that cannot be built or a session
// voxel out of range.
std::unique_ptr<rt::GraspSequencer> MakeReplayPipeline(
    const ReplayOptions& o, const std::optional<io::SessionDescription>& session, ClawUse* use,
    rt::GraspSequencer::GraspEndCallback on_grasp_end) {
  auto make = [&](claw::ClawModel model, const PipelineConfig& config) {
    return std::make_unique<rt::GraspSequencer>(config, std::move(model),
                                                rt::GraspSequencerConfig{}, on_grasp_end);
  };
  PipelineConfig config = o.pipeline;
  if (session && session->workspace_G && !o.workspace_given) {
    config.workspace.min_G = session->workspace_G->min();
    config.workspace.max_G = session->workspace_G->max();
  }
  if (session) {
    // What of it is used keeps the config file's limits (as on the bus).
    io::SessionDescription used = *session;
    if (o.voxel_given) used.voxel_m = 0.0;
    if (o.workspace_given) used.workspace_G.reset();
    if (o.T_C_B) used.T_C_B = Eigen::Isometry3d::Identity();
    std::string why;
    if (!io::SessionWithinLimits(used, &why)) {
      throw std::runtime_error("the recording's session description " + why +
                               " (override it: --voxel-m, --config)");
    }
  }
  if (session && session->voxel_m > 0.0 && !o.voxel_given) {
    SetVoxel(session->voxel_m, o.sdf_trunc_voxels, &config);
  }
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
    return make(std::move(model), config);
  }
  if (session) {
    use->label = SessionClawLabel(*session);
    use->from = "session description";
    return make(MakeSessionClaw(*session, o.claw_mesh_root), config);
  }
  use->label = "three-finger";
  use->from = "default";
  return make(claw::ClawModel::ThreeFinger(), config);
}

double Ms(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
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

// Where an earlier grasp's model goes, beside the output OUT/STEM.EXT:
// STEM.grasp<ID>.EXT for the first grasp with that id, and
// STEM.grasp<ID>-<N>.EXT for its N-th (N >= 2; a robot that numbers its
// grasps 1, 2, 1, 2): no grasp's model replaces another's.
std::string GraspModelPath(const std::string& output_path, int64_t grasp_id, int occurrence) {
  const std::filesystem::path out(output_path);
  std::string name = out.stem().string() + ".grasp" + std::to_string(grasp_id);
  if (occurrence > 1) name += "-" + std::to_string(occurrence);
  return (out.parent_path() / (name + out.extension().string())).string();
}

const char* HoleKindName(HoleKind kind) {
  return kind == HoleKind::kClaw ? "claw" : "missing_surface";
}

}  // namespace

int RunReplay(const Args& args) {
  for (const std::string& a : args) {
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
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
    std::fprintf(stderr, "graspfill replay: %s\n%s", e.what(), kUsage);
    return 2;
  } catch (const rt::ConfigError& e) {
    std::fprintf(stderr, "graspfill replay: --config: %s\n", e.what());
    return 2;
  }
  // Before the log is read: an output that cannot be written (its folder
  // missing or read-only, a folder, a link or an existing file without
  // --force) is found now, not after the whole replay.
  try {
    io::CheckOutputFile(o.output_path, o.force);
    if (!o.mesh_out.empty()) io::CheckOutputFile(o.mesh_out, o.force);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill replay: %s\n", ErrorText(e).c_str());
    return 1;
  }
  if (!o.preview_dir.empty() && !PreparePreview(o.preview_dir, o.output_path, o.force, "replay")) {
    return 1;
  }

  rt::LcmLogSource::Config source_config;
  source_config.path = o.log_path;
  source_config.channels = o.channels;
  source_config.session_events = true;
  if (o.T_C_B) {  // the config's hand-eye over the session descriptions'
    source_config.T_C_B = *o.T_C_B;
    source_config.T_C_B_from_session = false;
  }
  if (o.intrinsics) {
    source_config.intrinsics = o.intrinsics;
    source_config.intrinsics_from_session = false;
  }
  source_config.gripper_clock_offset_us = o.clock_offset_us;
  source_config.max_depth_pixels = o.max_depth_pixels;
  auto log_source = std::make_unique<rt::LcmLogSource>(source_config);  // throws on a bad file
  const rt::LcmLogSource& log = *log_source;  // for its counters, once at the end
  // Decoding runs ahead on a second thread, overlapping the pipeline.
  rt::PrefetchingSource source(std::move(log_source));
  // The grasps' final models as they end (a log of several grasps), with
  // what the camera saw of each; the last one comes from Finish below.
  struct GraspModel {
    ObjectCloud cloud;
    evidence::VisibilityRecord seen;
  };
  std::vector<GraspModel> ended;
  ClawUse claw_use;
  // The sequencer is made at the first depth or gripper event, once the
  // session description at the head of the recording (if any) is read.
  rt::SequencerFeed feed(
      [&](const std::optional<io::SessionDescription>& s) {
        return MakeReplayPipeline(o, s, &claw_use,
                                  [&](const ObjectCloud& c, const evidence::VisibilityRecord& r) {
                                    ended.push_back(GraspModel{c, r});
                                  });
      },
      o.skip_bad_frames);
  const auto t_start = std::chrono::steady_clock::now();
  rt::SessionLoopLimits limits;
  std::optional<ProgressLine> progress;
  if (ProgressWanted()) {
    progress.emplace("replay", "frames", CountDepthFrames(o.log_path, o.channels.depth));
    limits.on_tick = [&] { progress->Update(feed.depth_events()); };
    limits.tick_ms = 200;
  }
  rt::SessionLoop loop(limits);
  const rt::LoopEnd end = loop.Run(&source, &feed);
  progress.reset();  // the line erased before anything else is printed
  if (feed.late_sessions() > 0) {
    std::fprintf(stderr, "graspfill replay: warning: the session description at utime %lld "
                 "comes after the recording's first one or its first events; its claw, "
                 "workspace box and voxel are ignored\n",
                 static_cast<long long>(feed.late_session_utime()));
  }
  if (end == rt::LoopEnd::kSinkStopped) {
    std::fprintf(stderr, "graspfill replay: bad event in '%s': %s\n"
                 "(pass --skip-bad-frames to skip such events)\n",
                 o.log_path.c_str(), feed.first_error().c_str());
    return 1;
  }
  const std::optional<io::SessionDescription>& session = feed.session();
  const int64_t sessions = feed.sessions();
  const int64_t bad_events = feed.bad_events();
  if (log.partial_last_event()) {
    // A recording cut short (crash, kill, power cut, full disk): the whole
    // events before its partial last one are the log.
    std::fprintf(stderr, "graspfill replay: note: log '%s' ends in a partial event (%lld bytes "
                 "after its %lld whole events: a recording cut short), skipped\n",
                 o.log_path.c_str(), static_cast<long long>(log.unread_bytes()),
                 static_cast<long long>(log.events_read()));
  } else if (log.truncated()) {
    std::fprintf(stderr, "graspfill replay: log '%s' is truncated after %lld events (%s)\n",
                 o.log_path.c_str(), static_cast<long long>(log.events_read()),
                 log.stop_reason().c_str());
    return 1;
  }
  if (feed.depth_events() == 0) {
    std::string seen;
    for (const std::string& c : log.channels_seen()) seen += (seen.empty() ? "" : ", ") + c;
    std::fprintf(stderr, "graspfill replay: no depth frames on channel '%s' in '%s' (channels: %s)\n",
                 o.channels.depth.c_str(), o.log_path.c_str(), seen.empty() ? "none" : seen.c_str());
    return 1;
  }
  rt::GraspSequencer& sequencer = *feed.sequencer();  // made: there was a depth event
  const auto t_fused = std::chrono::steady_clock::now();
  sequencer.Finish();  // the last grasp's model, to the callback like the others
  ObjectCloud cloud = std::move(ended.back().cloud);
  const evidence::VisibilityRecord& last_seen = ended.back().seen;
  const auto t_extracted = std::chrono::steady_clock::now();
  const PipelineStats stats = sequencer.stats();
  if (stats.frames_integrated == 0 && stats.frames_skipped_refine > 0) {
    std::fprintf(stderr, "graspfill replay: pose refinement rejected every posed frame (%s)\n"
                 "(pass --no-refine to fuse at the logged poses)\n", RefineSummary(sequencer.pipeline()).c_str());
    return 1;
  }
  if (stats.frames_integrated == 0) {
    std::fprintf(stderr, "graspfill replay: no depth frame had a gripper pose within %.1f ms "
                 "(%lld frames, %lld gripper states)\n", o.pipeline.max_pose_gap_us / 1000.0,
                 static_cast<long long>(stats.frames_in), static_cast<long long>(stats.states_in));
    return 1;
  }
  // A log of several grasps: every grasp's model but the last beside the
  // output (the last is the output itself), as GraspModelPath names them.
  nlohmann::ordered_json grasps_json = nlohmann::json::array();
  std::map<int64_t, int> times_seen;  // by grasp id: a robot may reuse ids
  for (size_t g = 0; g + 1 < ended.size(); ++g) {
    ObjectCloud& model = ended[g].cloud;
    const std::string path = GraspModelPath(o.output_path, model.grasp_id, ++times_seen[model.grasp_id]);
    std::string status = "off";
    if (o.repair) {
      try {
        status = rt::RepairObjectCloud(rt::GripperFrameRepairConfig(o.repair_config), &model,
                                       o.evidence ? &ended[g].seen : nullptr).StatusText();
      } catch (const std::exception& e) {
        status = "failed: " + ErrorText(e);
      }
    }
    try {
      io::CheckOutputFile(path, o.force);
      io::WriteCloudPly(path, model, io::ReplaceIf(o.force));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "graspfill replay: grasp %lld: %s\n",
                   static_cast<long long>(model.grasp_id), ErrorText(e).c_str());
      return 1;
    }
    if (o.publish) {
      rt::LcmPublisher publisher(o.lcm_url);
      publisher.PublishCloud(o.channels.object_cloud, model);
    }
    grasps_json.push_back({{"grasp_id", model.grasp_id}, {"points", model.size()},
                           {"repair", status}, {"output", path}});
    if (!o.json) {
      std::printf("grasp %lld: %zu points -> %s (repair: %s)\n",
                  static_cast<long long>(model.grasp_id), model.size(), path.c_str(),
                  status.c_str());
    }
  }
  const size_t fused_points = cloud.size();
  std::optional<ObjectCloud> fused;  // the preview's "before"
  if (!o.preview_dir.empty() && o.repair) fused = cloud;
  std::optional<repair::RepairReport> repair_report;
  if (o.repair) {
    try {
      repair_report = rt::RepairObjectCloud(rt::GripperFrameRepairConfig(o.repair_config), &cloud,
                                            o.evidence ? &last_seen : nullptr);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "graspfill replay: hole repair failed on the fused cloud (%zu points): %s\n"
                   "(pass --no-repair to write the fused cloud as is)\n", fused_points, ErrorText(e).c_str());
      return 1;
    }
  }
  const auto t_repaired = std::chrono::steady_clock::now();
  try {
    io::WriteCloudPly(o.output_path, cloud, io::ReplaceIf(o.force));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill replay: %s\n", ErrorText(e).c_str());
    return 1;
  }
  const auto t_written = std::chrono::steady_clock::now();
  std::string preview_path;
  if (!o.preview_dir.empty()) {
    try {
      preview_path = WritePreview(o.preview_dir, o.output_path, fused ? &*fused : nullptr, cloud, o.force);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "graspfill replay: %s\n", ErrorText(e).c_str());
      return 1;
    }
  }
  if (o.publish) {
    rt::LcmPublisher publisher(o.lcm_url);
    publisher.PublishCloud(o.channels.object_cloud, cloud);
  }
  const auto t_end = std::chrono::steady_clock::now();
  // The collision mesh of the model just written (the last grasp's).
  nlohmann::ordered_json mesh_report;
  if (!o.mesh_out.empty()) {
    try {
      mesh_report = WriteCollisionMesh(o.mesh_out, cloud, o.force);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "graspfill replay: collision mesh: %s\n", ErrorText(e).c_str());
      return 1;
    }
  }

  const double replay_ms = Ms(t_fused - t_start);
  const double fps = stats.frames_integrated / (replay_ms / 1000.0);
  nlohmann::ordered_json report;
  report["log"] = o.log_path;
  report["output"] = o.output_path;
  report["frames_read"] = stats.frames_in;
  report["frames_used"] = stats.frames_integrated;
  report["frames_skipped_no_pose"] = stats.frames_skipped_no_pose;
  report["frames_dropped"] = stats.frames_dropped;
  report["frames_bad"] = stats.frames_bad;
  report["frames_decimated"] = stats.frames_decimated;
  report["bad_events_skipped"] = bad_events;
  report["gripper_states"] = stats.states_in;
  report["gripper_states_rejected"] = stats.states_rejected;
  report["claw"] = {{"name", claw_use.label}, {"from", claw_use.from}};
  report["config"] = o.config_path.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.config_path);
  if (session) {
    report["session"] = {{"software_version", session->software_version},
                         {"utime", session->utime},
                         {"claw", SessionClawLabel(*session)},
                         {"descriptions", sessions}};
  } else {
    report["session"] = nullptr;
  }
  report["refine"] = RefineJson(sequencer.pipeline());
  report["track_object"] = TrackJson(sequencer.pipeline());
  report["points"] = cloud.size();
  report["grasp_id"] = cloud.grasp_id;
  grasps_json.push_back({{"grasp_id", cloud.grasp_id}, {"points", cloud.size()},
                         {"output", o.output_path}});
  report["grasps"] = grasps_json;
  report["clock_jumps"] = sequencer.counters().clock_jumps;
  report["frames_skipped_clock_jump"] = sequencer.counters().skipped_clock_jump;
  report["published"] = o.publish ? o.channels.object_cloud : "";
  report["preview"] = preview_path.empty() ? nlohmann::json(nullptr) : nlohmann::json(preview_path);
  report["software_version"] = io::SoftwareVersion();
  const double repair_ms = Ms(t_repaired - t_extracted);
  const size_t points_added = cloud.size() - fused_points;
  if (repair_report) {
    nlohmann::ordered_json holes = nlohmann::json::array();
    for (const HoleSummary& h : repair_report->holes) {
      holes.push_back({{"kind", HoleKindName(h.kind)},
                       {"boundary_points", h.boundary_points},
                       {"points_added", h.points_added},
                       {"unobserved", h.unobserved},
                       {"confidence", h.confidence}});
    }
    report["repair"] = {{"status", repair_report->StatusText()},
                        {"points_added", points_added},
                        {"symmetric", repair_report->symmetric},
                        {"symmetry_reason", repair_report->symmetry_reason},
                        {"top_completion", repair_report->top_completion},
                        {"top_confidence", repair_report->top_confidence},
                        {"holes", holes},
                        {"claw_holes_left_open", repair_report->claw_holes_left_open},
                        {"evidence", EvidenceJson(repair_report->evidence)},
                        {"ms", repair_ms}};
  } else {
    report["repair"] = nullptr;
  }
  report["timings_ms"] = {
      {"crop_per_frame", stats.crop.mean_ms()},
      {"mask_per_frame", stats.mask.mean_ms()},
      {"integrate_per_frame", stats.integrate.mean_ms()},
      {"visibility_per_frame", stats.visibility.mean_ms()},
      {"replay_total", replay_ms},
      {"extract", Ms(t_extracted - t_fused)},
      {"repair", repair_ms},
      {"write_ply", Ms(t_written - t_repaired)},
      {"publish", Ms(t_end - t_written)}};
  report["replay_fps"] = fps;
  if (!o.mesh_out.empty()) report["mesh"] = mesh_report;
  if (o.json) {
    std::printf("%s\n", report.dump(2).c_str());
  } else {
    std::printf("replayed %s: %lld frames read, %lld used, %lld skipped (no pose), %lld bad\n",
                o.log_path.c_str(), static_cast<long long>(stats.frames_in),
                static_cast<long long>(stats.frames_integrated),
                static_cast<long long>(stats.frames_skipped_no_pose),
                static_cast<long long>(stats.frames_bad + bad_events));
    const std::string claw_from = claw_use.from == "default"
                                      ? "default: the recording has no session description"
                                      : "from the " + claw_use.from;
    std::printf("claw: %s (%s)\n", claw_use.label.c_str(), claw_from.c_str());
    std::printf("%s\n", RefineSummary(sequencer.pipeline()).c_str());
    if (o.pipeline.track_object.enabled) {
      std::printf("%s\n", TrackSummary(sequencer.pipeline()).c_str());
    }
    std::printf("object cloud: %zu points -> %s%s%s\n", cloud.size(), o.output_path.c_str(),
                o.publish ? ", published on " : "", o.publish ? o.channels.object_cloud.c_str() : "");
    if (!preview_path.empty()) std::printf("preview: %s\n", preview_path.c_str());
    std::printf("per frame: crop %.3f ms, claw mask %.3f ms, integrate %.3f ms; "
                "replay %.1f fps; extract %.1f ms\n",
                stats.crop.mean_ms(), stats.mask.mean_ms(), stats.integrate.mean_ms(), fps,
                Ms(t_extracted - t_fused));
    if (!repair_report) {
      std::printf("repair: off (--no-repair)\n");
    } else if (repair_report->status != repair::RepairStatus::kRepaired) {
      std::printf("repair: %s (%.1f ms)\n", repair_report->StatusText().c_str(), repair_ms);
    } else {
      int claw_holes = 0, missing_surfaces = 0;
      for (const HoleSummary& h : repair_report->holes) {
        ++(h.kind == HoleKind::kClaw ? claw_holes : missing_surfaces);
      }
      std::string symmetry = repair_report->symmetric ? ", top by symmetry" : "";
      if (!repair_report->symmetric && !repair_report->symmetry_reason.empty()) {
        symmetry = "; no symmetry: " + repair_report->symmetry_reason;
      }
      const std::string left_open =
          repair_report->claw_holes_left_open > 0
              ? ", " + std::to_string(repair_report->claw_holes_left_open) + " of them left open"
              : "";
      std::printf("repair: %s; %zu points added (%d claw holes%s, %d missing top%s) in %.1f ms\n",
                  repair_report->StatusText().c_str(), points_added, claw_holes, left_open.c_str(),
                  missing_surfaces, symmetry.c_str(), repair_ms);
    }
    if (!o.mesh_out.empty()) PrintCollisionMesh(mesh_report);
  }
  return 0;
}

}  // namespace graspfill::cli
