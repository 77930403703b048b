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
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "claw_option.hpp"
#include "commands.hpp"
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
    "  --claw SPEC           three-finger (default), parallel, or a claw description .json\n"
    "  --claw-mesh-root DIR  where the description's meshes are\n"
    "  --publish-every N     publish the cloud every N fused frames (default 30)\n"
    "  --no-repair           publish the fused cloud as is (no hole repair)\n"
    "  --repair-mode MODE    paper: the repair as published; best (default): graspfill's.\n"
    "                        The repair runs beside fusion; a cloud that comes while one\n"
    "                        is repaired waits, and a newer one replaces it\n"
    "  --duration-s S        stop after S seconds (default: until Ctrl-C or end of .oni)\n"
    "  --depth-channel C / --gripper-channel C / --cloud-channel C / --status-channel C\n";

std::atomic<bool> g_interrupted{false};

}  // namespace

int RunLive(const Args& args) {
  rt::OpenNI2Source::Config camera;
  rt::LcmBusSubscriber::Config bus;
  rt::GraspModuleConfig module_config;
  std::string claw_spec = "three-finger", mesh_root;
  double duration_s = 0.0;
  double idle_exit_s = 0.0;
  bool depth_from_lcm = false;
  bool repair_enabled = true;
  repair::RepairConfig repair_config;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const bool has_value = i + 1 < args.size();
    if (a == "--help" || a == "-h") { std::fputs(kUsage, stdout); return 0; }
    else if (a == "--device" && has_value) camera.uri = args[++i];
    else if (a == "--depth-from-lcm") depth_from_lcm = true;
    else if (a == "--idle-exit-s" && has_value) idle_exit_s = std::stod(args[++i]);
    else if (a == "--depth-channel" && has_value) bus.channels.depth = args[++i];
    else if (a == "--lcm-url" && has_value) bus.url = args[++i];
    else if (a == "--claw" && has_value) claw_spec = args[++i];
    else if (a == "--claw-mesh-root" && has_value) mesh_root = args[++i];
    else if (a == "--publish-every" && has_value) module_config.extract_every_n_frames = std::stoi(args[++i]);
    else if (a == "--no-repair") repair_enabled = false;
    else if (a == "--repair-mode" && has_value) {
      const std::string mode = args[++i];
      if (mode == "paper") repair_config.mode = repair::RepairMode::kPaper;
      else if (mode == "best") repair_config.mode = repair::RepairMode::kBest;
      else {
        std::fprintf(stderr, "graspfill live: --repair-mode must be paper or best, not '%s'\n%s",
                     mode.c_str(), kUsage);
        return 2;
      }
    }
    else if (a == "--duration-s" && has_value) duration_s = std::stod(args[++i]);
    else if (a == "--gripper-channel" && has_value) bus.channels.gripper_state = args[++i];
    else if (a == "--cloud-channel" && has_value) bus.channels.object_cloud = args[++i];
    else if (a == "--status-channel" && has_value) bus.channels.status = args[++i];
    else {
      std::fprintf(stderr, "graspfill live: bad option '%s'\n%s", a.c_str(), kUsage);
      return 2;
    }
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
  // to a stage that is gone.
  rt::GraspModule module(module_config, MakeClaw(claw_spec, mesh_root),
                         [&](const ObjectCloud& cloud, const evidence::VisibilityRecord& seen) {
                           if (repair_stage) repair_stage->Submit(cloud, &seen);  // never waits
                           else publish_cloud(cloud);
                         });
  using Clock = std::chrono::steady_clock;
  std::atomic<int64_t> last_depth_ns{0};  // steady clock of the last depth frame
  auto push_depth = [&](const DepthFrame& f) {
    module.PushDepthFrame(f);
    last_depth_ns = Clock::now().time_since_epoch().count();
  };
  rt::LcmBusSubscriber subscriber(
      bus, [&](const GripperState& s) { module.PushGripperState(s); },
      depth_from_lcm ? rt::LcmBusSubscriber::DepthCallback(push_depth) : nullptr);
  std::signal(SIGINT, [](int) { g_interrupted = true; });
  std::signal(SIGTERM, [](int) { g_interrupted = true; });

  const auto start = Clock::now();
  auto last_status = start;
  DepthFrame frame;
  while (!g_interrupted) {
    const auto now = Clock::now();
    if (duration_s > 0 && std::chrono::duration<double>(now - start).count() > duration_s) break;
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
    if (now - last_status > std::chrono::seconds(1)) {
      const rt::GraspModuleStatus s = module.status();
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
  const ObjectCloud fused = module.Finish();
  size_t published_points = fused.size();
  if (repair_stage) {
    repair_stage->Drain();  // the last cloud out repaired, not dropped
    published_points = repair_stage->status().last_points_out;
  }
  const rt::GraspModuleStatus s = module.status();
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
