// graspfill live: the grasp-and-model session. Depth from an OpenNI2 device
// (or an .oni recording, or depth_image_t on the LCM bus), gripper states
// from the robot over LCM, fusion on the module's worker thread, then the
// hole repair (claw holes and the unseen top, unless --no-repair) on a
// repair stage's thread of its own, and the object cloud published over LCM.
//
// A repair takes ~100-200 ms, a depth frame must be fused within ~33 ms: the
// fusion worker only hands each extracted cloud to the repair stage's
// one-slot mailbox and goes on. When clouds come faster than repairs, the
// one waiting is replaced by the newer (counted as superseded), so the
// planner always gets the freshest model. The published cloud is as
// `graspfill replay` writes it: fused points first, the repair's after,
// with its holes and "repair_" timings.
//
// The claw: --claw if given. Otherwise, with --depth-from-lcm, the claw of
// the session description (session_description_t on GRASPFILL_SESSION) that
// comes before the first depth frame (as lcm-logplayer plays a recording
// graspfill wrote), with its workspace box and voxel size: the module starts
// once it has one, or once the first depth frame came without one (then
// the three-finger default). A session description that arrives later, or
// whose claw is not --claw's, is warned about. With OpenNI2 depth the bus's
// session description is not waited for (the claw is --claw or the
// default). Every session description's hand-eye T_C_B and intrinsics
// override apply to the gripper states and depth images received after it.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "claw_option.hpp"
#include "commands.hpp"
#include "number_parsing.hpp"
#include "graspfill/repair/repairer.hpp"
#include "module/cloud_repair.hpp"
#include "module/grasp_module.hpp"
#include "module/repair_stage.hpp"
#include "sinks/lcm_publisher.hpp"
#include "sources/lcm_bus_subscriber.hpp"
#include "sources/openni2_source.hpp"

namespace graspfill::cli {
namespace {

constexpr const char* kUsage =
    "usage: graspfill live [options]\n"
    "  --device URI          OpenNI2 device URI or an .oni file (default: any device)\n"
    "  --depth-from-lcm      take depth_image_t from the LCM bus instead of OpenNI2\n"
    "                        (a camera driver on another process, or lcm-logplayer)\n"
    "  --idle-exit-s S       stop when no depth frame came for S seconds after the first\n"
    "  --lcm-url URL         LCM bus for gripper states and the cloud (default: LCM's default)\n"
    "  --claw SPEC           three-finger, parallel, or a claw description .json (default:\n"
    "                        with --depth-from-lcm the claw of the session description on\n"
    "                        the bus before the first depth frame, else three-finger)\n"
    "  --claw-mesh-root DIR  where the description's meshes are\n"
    "  --publish-every N     publish the cloud every N fused frames, 0..100000 (default 30;\n"
    "                        0: only at the end)\n"
    "  --no-repair           publish the fused cloud as is (no hole repair)\n"
    "  --repair-mode MODE    paper: the repair as published; best (default): graspfill's.\n"
    "                        The repair runs beside fusion; a cloud that comes while one\n"
    "                        is repaired waits, and a newer one replaces it\n"
    "  --duration-s S        stop after S seconds (default: until Ctrl-C or end of .oni)\n"
    "  --depth-channel C / --gripper-channel C / --cloud-channel C / --status-channel C /\n"
    "  --session-channel C\n";

std::atomic<bool> g_interrupted{false};

// What the bus delivers before the module exists (it waits for its claw),
// and the first session description received. Callbacks run on the bus
// thread; the module's Push* never wait, so the lock is held only briefly.
struct Intake {
  static constexpr size_t kMaxEarlyStates = 64;  // as the module's state queue
  static constexpr size_t kMaxEarlyFrames = 4;   // as the module's frame queue

  std::mutex mutex;
  rt::GraspModule* module{nullptr};
  std::deque<GripperState> states;
  std::deque<DepthFrame> frames;
  std::optional<io::SessionDescription> first_session;
};

}  // namespace

int RunLive(const Args& args) {
  rt::OpenNI2Source::Config camera;
  rt::LcmBusSubscriber::Config bus;
  rt::GraspModuleConfig module_config;
  std::optional<std::string> claw_spec;
  std::string mesh_root;
  double duration_s = 0.0;
  double idle_exit_s = 0.0;
  bool depth_from_lcm = false;
  bool repair_enabled = true;
  repair::RepairConfig repair_config;
  constexpr double kMaxSeconds = 7 * 24 * 3600.0;  // a week
  try {
    for (size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      const bool has_value = i + 1 < args.size();
      if (a == "--help" || a == "-h") { std::fputs(kUsage, stdout); return 0; }
      else if (a == "--device" && has_value) camera.uri = args[++i];
      else if (a == "--depth-from-lcm") depth_from_lcm = true;
      else if (a == "--idle-exit-s" && has_value) idle_exit_s = ParseDouble(a, args[++i], 0.0, kMaxSeconds, "s");
      else if (a == "--depth-channel" && has_value) bus.channels.depth = args[++i];
      else if (a == "--lcm-url" && has_value) bus.url = args[++i];
      else if (a == "--claw" && has_value) claw_spec = args[++i];
      else if (a == "--claw-mesh-root" && has_value) mesh_root = args[++i];
      else if (a == "--publish-every" && has_value) {
        module_config.extract_every_n_frames = ParseInteger<int>(a, args[++i], 0, 100000);
      }
      else if (a == "--no-repair") repair_enabled = false;
      else if (a == "--repair-mode" && has_value) {
        const std::string mode = args[++i];
        if (mode == "paper") repair_config.mode = repair::RepairMode::kPaper;
        else if (mode == "best") repair_config.mode = repair::RepairMode::kBest;
        else throw UsageError("--repair-mode must be paper or best, not '" + mode + "'");
      }
      else if (a == "--duration-s" && has_value) duration_s = ParseDouble(a, args[++i], 0.0, kMaxSeconds, "s");
      else if (a == "--gripper-channel" && has_value) bus.channels.gripper_state = args[++i];
      else if (a == "--cloud-channel" && has_value) bus.channels.object_cloud = args[++i];
      else if (a == "--status-channel" && has_value) bus.channels.status = args[++i];
      else if (a == "--session-channel" && has_value) bus.channels.session = args[++i];
      else throw UsageError("bad option '" + a + "'");
    }
  } catch (const UsageError& e) {
    std::fprintf(stderr, "graspfill live: %s\n%s", e.what(), kUsage);
    return 2;
  }
  std::unique_ptr<rt::OpenNI2Source> camera_source;
  if (!depth_from_lcm) camera_source = std::make_unique<rt::OpenNI2Source>(camera);  // throws if none
  rt::LcmPublisher publisher(bus.url);
  // Clouds go out from the repair stage's (or the fusion worker's) thread,
  // status from this one; the publisher wants its calls serialized.
  std::mutex publisher_mutex;
  auto publish_cloud = [&](const ObjectCloud& cloud) {
    std::lock_guard<std::mutex> lock(publisher_mutex);
    publisher.PublishCloud(bus.channels.object_cloud, cloud);
  };
  std::unique_ptr<rt::RepairStage> repair_stage;
  if (repair_enabled) {
    repair_stage = std::make_unique<rt::RepairStage>(rt::GripperFrameRepairConfig(repair_config),
                                                     publish_cloud);
  }
  // Declared after the stage, so destroyed before it: no cloud is submitted
  // to a stage that is gone; made once its claw is known (see the file
  // comment), and declared before the subscriber, which feeds it.
  std::unique_ptr<rt::GraspModule> module;
  Intake intake;
  using Clock = std::chrono::steady_clock;
  std::atomic<int64_t> last_depth_ns{0};  // steady clock of the last depth frame
  auto push_state = [&](const GripperState& s) {
    std::lock_guard<std::mutex> lock(intake.mutex);
    if (intake.module != nullptr) {
      intake.module->PushGripperState(s);
      return;
    }
    if (intake.states.size() == Intake::kMaxEarlyStates) intake.states.pop_front();
    intake.states.push_back(s);
  };
  auto push_depth = [&](const DepthFrame& f) {
    {
      std::lock_guard<std::mutex> lock(intake.mutex);
      if (intake.module != nullptr) {
        intake.module->PushDepthFrame(f);
      } else {
        if (intake.frames.size() == Intake::kMaxEarlyFrames) intake.frames.pop_front();
        intake.frames.push_back(f);
      }
    }
    last_depth_ns = Clock::now().time_since_epoch().count();
  };
  auto on_session = [&](const io::SessionDescription& session) {
    std::lock_guard<std::mutex> lock(intake.mutex);
    if (!intake.first_session) intake.first_session = session;
  };
  rt::LcmBusSubscriber subscriber(
      bus, push_state, depth_from_lcm ? rt::LcmBusSubscriber::DepthCallback(push_depth) : nullptr,
      on_session);
  std::signal(SIGINT, [](int) { g_interrupted = true; });
  std::signal(SIGTERM, [](int) { g_interrupted = true; });

  const auto start = Clock::now();
  auto out_of_time = [&] {
    return duration_s > 0 &&
           std::chrono::duration<double>(Clock::now() - start).count() > duration_s;
  };
  // Without --claw, depth from the bus: wait for the session description
  // or the first depth frame, whichever comes first.
  if (!claw_spec && depth_from_lcm) {
    for (;;) {
      {
        std::lock_guard<std::mutex> lock(intake.mutex);
        if (intake.first_session || !intake.frames.empty()) break;
      }
      if (g_interrupted || out_of_time()) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  std::optional<io::SessionDescription> session;  // the one the module was made with
  {
    std::lock_guard<std::mutex> lock(intake.mutex);
    if (!claw_spec && depth_from_lcm) session = intake.first_session;
  }
  claw::ClawModel claw_model = claw::ClawModel::ThreeFinger();
  std::string claw_label = "three-finger";
  if (claw_spec) {
    claw_model = MakeClaw(*claw_spec, mesh_root);
    claw_label = *claw_spec;
    std::printf("live: claw %s (from the command line)\n", claw_label.c_str());
  } else if (session) {
    claw_model = MakeSessionClaw(*session, mesh_root);
    claw_label = SessionClawLabel(*session);
    if (session->workspace_G) {
      module_config.pipeline.workspace.min_G = session->workspace_G->min();
      module_config.pipeline.workspace.max_G = session->workspace_G->max();
    }
    if (session->voxel_m > 0.0) {
      if (session->voxel_m < kMinVoxelM || session->voxel_m > kMaxVoxelM) {
        std::fprintf(stderr, "graspfill live: the session description asks for a voxel of %g m, "
                     "outside %g..%g m\n", session->voxel_m, kMinVoxelM, kMaxVoxelM);
        return 1;
      }
      module_config.pipeline.tsdf.voxel_m = session->voxel_m;
      module_config.pipeline.tsdf.sdf_trunc_m = 4.0 * session->voxel_m;
    }
    std::printf("live: claw %s (from the session description on %s)\n", claw_label.c_str(),
                bus.channels.session.c_str());
  } else {
    std::printf("live: claw three-finger (default%s)\n",
                depth_from_lcm ? ": no session description before the first depth frame" : "");
  }
  std::fflush(stdout);
  module = std::make_unique<rt::GraspModule>(
      module_config, claw_model,
      [&](const ObjectCloud& cloud, const evidence::VisibilityRecord& seen) {
        if (repair_stage) repair_stage->Submit(cloud, &seen);  // never waits
        else publish_cloud(cloud);
      });
  {
    std::lock_guard<std::mutex> lock(intake.mutex);
    for (const GripperState& s : intake.states) module->PushGripperState(s);
    for (const DepthFrame& f : intake.frames) module->PushDepthFrame(f);
    intake.states.clear();
    intake.frames.clear();
    intake.module = module.get();
  }
  // Session descriptions other than the one the module was made with: a
  // claw that differs from the one in use is warned about, once.
  bool session_checked = session.has_value();
  auto check_session = [&] {
    if (session_checked) return;
    std::optional<io::SessionDescription> received;
    {
      std::lock_guard<std::mutex> lock(intake.mutex);
      received = intake.first_session;
    }
    if (!received) return;
    session_checked = true;
    bool same = false;
    try {
      same = SameClaw(claw_model, MakeSessionClaw(*received, mesh_root));
    } catch (const std::exception&) {
      same = claw_model.name() == received->claw_name;
    }
    if (same) return;
    if (claw_spec) {
      std::fprintf(stderr, "graspfill live: warning: --claw %s differs from the claw of the "
                   "session description on %s (%s); using %s\n", claw_spec->c_str(),
                   bus.channels.session.c_str(), SessionClawLabel(*received).c_str(),
                   claw_spec->c_str());
    } else {
      std::fprintf(stderr, "graspfill live: warning: the session description on %s came after "
                   "the first depth frame; its claw %s is ignored, using %s\n",
                   bus.channels.session.c_str(), SessionClawLabel(*received).c_str(),
                   claw_label.c_str());
    }
  };

  auto last_status = start;
  DepthFrame frame;
  while (!g_interrupted) {
    const auto now = Clock::now();
    if (out_of_time()) break;
    const int64_t last_ns = last_depth_ns;
    if (idle_exit_s > 0 && last_ns != 0 &&
        (now.time_since_epoch().count() - last_ns) * 1e-9 > idle_exit_s) {
      break;
    }
    if (camera_source) {
      const rt::FrameResult r = camera_source->Next(&frame);
      if (r == rt::FrameResult::kEndOfStream) break;
      if (r == rt::FrameResult::kOk) push_depth(frame);
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));  // the bus thread pushes
    }
    check_session();
    if (now - last_status > std::chrono::seconds(1)) {
      const rt::GraspModuleStatus s = module->status();
      io::ModuleStatus status;
      status.utime = frame.utime;
      status.frames_in = s.frames_in;
      status.frames_used = s.pipeline.frames_integrated;
      status.frames_skipped = s.pipeline.frames_skipped_no_pose + s.pipeline.frames_bad;
      status.frames_dropped = s.frames_dropped + s.pipeline.frames_dropped;
      status.last_frame_ms = s.pipeline.crop.last_ms + s.pipeline.mask.last_ms +
                             s.pipeline.integrate.last_ms;
      status.state = "running";
      std::lock_guard<std::mutex> lock(publisher_mutex);
      publisher.PublishStatus(bus.channels.status, status);
      last_status = now;
    }
  }
  const ObjectCloud fused = module->Finish();
  size_t published_points = fused.size();
  if (repair_stage) {
    repair_stage->Drain();  // the last cloud out repaired, not dropped
    published_points = repair_stage->status().last_points_out;
  }
  const rt::GraspModuleStatus s = module->status();
  std::printf("live: %lld frames in, %lld fused, %lld dropped; %lld gripper states; "
              "cloud of %zu points published on %s\n",
              static_cast<long long>(s.frames_in),
              static_cast<long long>(s.pipeline.frames_integrated),
              static_cast<long long>(s.frames_dropped),
              static_cast<long long>(subscriber.states_received()), published_points,
              bus.channels.object_cloud.c_str());
  if (repair_stage && repair_stage->status().submitted == 0) {
    std::printf("repair: no cloud to repair\n");
  } else if (repair_stage) {
    const rt::RepairStageStatus r = repair_stage->status();
    std::printf("repair: %lld clouds submitted, %lld repaired, %lld superseded, %lld failed; "
                "last: %s, %zu -> %zu points in %.1f ms\n",
                static_cast<long long>(r.submitted), static_cast<long long>(r.repaired),
                static_cast<long long>(r.superseded), static_cast<long long>(r.failed),
                r.last_status.c_str(), r.last_points_in, r.last_points_out, r.last_repair_ms);
  } else {
    std::printf("repair: off (--no-repair)\n");
  }
  return 0;
}

}  // namespace graspfill::cli
