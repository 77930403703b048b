// graspfill live: the grasp-and-model session. Depth from an OpenNI2 device
// (or an .oni recording), gripper states from the robot over LCM, the
// module on its worker thread, the object cloud published over LCM.
#include <atomic>
#include <chrono>
#include <csignal>
#include <memory>
#include <cstdio>
#include <string>
#include <thread>

#include "claw_option.hpp"
#include "commands.hpp"
#include "module/grasp_module.hpp"
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
  rt::GraspModule module(module_config, MakeClaw(claw_spec, mesh_root),
                         [&](const ObjectCloud& cloud) {
                           publisher.PublishCloud(bus.channels.object_cloud, cloud);
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
      publisher.PublishStatus(bus.channels.status, status);
      last_status = now;
    }
  }
  const ObjectCloud cloud = module.Finish();
  const rt::GraspModuleStatus s = module.status();
  std::printf("live: %lld frames in, %lld fused, %lld dropped; %lld gripper states; "
              "cloud of %zu points published on %s\n",
              static_cast<long long>(s.frames_in),
              static_cast<long long>(s.pipeline.frames_integrated),
              static_cast<long long>(s.frames_dropped),
              static_cast<long long>(subscriber.states_received()), cloud.size(),
              bus.channels.object_cloud.c_str());
  return 0;
}

}  // namespace graspfill::cli
