// graspfill bench live [LOG]: the live module against the clock. The
// recording is played in real time and faster (depth frames and gripper
// states at their recorded pace / speed) into the live module, in-process
// (memq: the frames handed to rt::LiveSession as a camera driver would) and
// across processes (udpm: a `graspfill live --depth-from-lcm` child, in a
// private network namespace), and the published clouds are received as a
// planner would. Per run: frames in / used / dropped, clouds and their rate,
// the latency from a frame's send to the receipt of the first cloud whose
// newest frame it is (p50/p95/p99/max), the repair's update and full times
// (from the module's status), RSS at the start and the end. The reference
// in the same run: the same with a full repair of every cloud.
//
// A grasp's final model (published when the session ends, after the idle
// rule's wait) is not counted in the cloud rate or the latency.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "claw_option.hpp"
#include "commands.hpp"
#include "data_paths.hpp"
#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/io/messages.hpp"
#include "error_text.hpp"
#include "module/cloud_repair.hpp"
#include "module/live_session.hpp"
#include "module/process_memory.hpp"
#include "module/sample_window.hpp"
#include "number_parsing.hpp"
#include "private_network.hpp"
#include "sources/lcm_log_source.hpp"

namespace graspfill::cli {
namespace {

using Clock = std::chrono::steady_clock;

std::string Usage() {
  return "usage: graspfill bench live [LOG] [--speeds 1,2,4] [--transport memq|udpm|both]\n"
         "                            [--repair incremental|full|both] [--publish-every N]\n"
         "                            [--soak-s S] [--heap-reserve-mb N] [--json]\n"
         "  LOG defaults to the bundled recording " +
         (BundledRecordingDir() / "recording.lcmlog").string() +
         "\n"
         "  --speeds LIST      playback speeds (default 1,2,4)\n"
         "  --transport T      memq: in-process; udpm: a `graspfill live` process over UDP\n"
         "                     multicast in a private network namespace (needs root; skipped\n"
         "                     with a note otherwise); both (default)\n"
         "  --repair R         incremental (the default of `live`), full (every cloud repaired\n"
         "                     in full: the reference) or both (default)\n"
         "  --publish-every N  a cloud every N fused frames, 1..1000 (default 3: 10 Hz at 30 fps)\n"
         "  --soak-s S         long mode: also play the recording in a loop at 1x in-process for\n"
         "                     S seconds (>= 60) and report RSS at minute 1 and at the end\n"
         "  --heap-reserve-mb N `graspfill live`'s --heap-reserve-mb, in-process and in the child\n"
         "                     (default " + std::to_string(kLiveHeapReserveMb) + "; 0: the allocator's defaults)\n";
}

double MsBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// The recording: read from the file as it plays in-process (as a replay
// does: holding 900 decoded frames would take GBs), raw in memory for the bus.
struct Recording {
  std::string path;
  std::optional<io::SessionDescription> session;
  std::vector<int64_t> depth_utimes;    // in log order
  std::vector<io::LogEvent> raw;        // every event of our channels, in log order
  std::vector<int64_t> raw_depth_utime; // beside raw: a depth frame's utime, else 0
  io::ChannelNames channels;
  int depth_frames{0};
  int64_t first_utime{0}, last_utime{0};  // of the depth frames
  double duration_s() const { return (last_utime - first_utime) * 1e-6; }
};

int64_t UtimeOf(const rt::SourceEvent& e) {
  return e.kind == rt::SourceEvent::Kind::kDepth ? e.depth.utime : e.gripper.utime;
}

std::unique_ptr<rt::LcmLogSource> OpenSource(const std::string& path) {
  rt::LcmLogSource::Config config;
  config.path = path;
  config.session_events = true;
  return std::make_unique<rt::LcmLogSource>(config);
}

Recording LoadRecording(const std::string& path) {
  Recording rec;
  rec.path = path;
  const auto source = OpenSource(path);
  rt::SourceEvent event;
  for (rt::FrameResult r; (r = source->Next(&event)) != rt::FrameResult::kEndOfStream;) {
    if (r != rt::FrameResult::kOk) continue;  // counted by replay; a benchmark plays the rest
    if (event.kind == rt::SourceEvent::Kind::kSession) {
      if (!rec.session) rec.session = event.session;
    } else if (event.kind == rt::SourceEvent::Kind::kDepth) {
      if (rec.depth_frames++ == 0) rec.first_utime = event.depth.utime;
      rec.last_utime = std::max(rec.last_utime, event.depth.utime);
      rec.depth_utimes.push_back(event.depth.utime);
    }
  }
  if (rec.depth_frames < 2) throw std::runtime_error("'" + path + "' has fewer than 2 depth frames");
  io::LcmLogReader reader(path);
  DepthFrame frame;
  std::string error;
  for (io::LogEvent e; reader.Next(&e) == io::LogReadResult::kEvent;) {
    int64_t utime = 0;
    if (e.channel == rec.channels.depth) {
      if (!io::DecodeDepthImage(e.data.data(), e.data.size(), &frame, &error)) continue;
      utime = frame.utime;
    } else if (e.channel != rec.channels.gripper_state && e.channel != rec.channels.session) {
      continue;
    }
    rec.raw.push_back(e);
    rec.raw_depth_utime.push_back(utime);
  }
  return rec;
}

struct RunSpec {
  std::string transport;  // "memq" or "udpm"
  double speed{1.0};
  bool incremental{true};
  int publish_every{3};
  double soak_s{0.0};  // > 0: loop the recording this long (memq, 1x)
  int heap_reserve_mb{kLiveHeapReserveMb};
};

struct RunResult {
  RunSpec spec;
  int64_t frames_sent{0};
  io::ModuleStatus last;  // the module's last status
  int64_t clouds{0};      // not counting finals
  double play_s{0.0};
  rt::Percentiles latency;
  double rss_start_mb{0.0}, rss_end_mb{0.0};
  double rss_minute1_mb{0.0};  // soak only
  std::string note;             // why the run did not happen, if it did not
};

// When each depth frame went out (by utime), and the clouds that came back.
class LatencyProbe {
 public:
  explicit LatencyProbe(const Recording& rec, int loops) {
    for (int loop = 0; loop < loops; ++loop) {
      for (const int64_t utime : rec.depth_utimes) index_.emplace(Shift(rec, utime, loop), index_.size());
    }
    sent_ns_ = std::vector<std::atomic<int64_t>>(index_.size());
  }
  static int64_t Shift(const Recording& rec, int64_t utime, int loop) {
    // One loop after another, a frame period apart: the clock never jumps back.
    const int64_t period = (rec.last_utime - rec.first_utime) / std::max(1, rec.depth_frames - 1);
    return utime + loop * (rec.last_utime - rec.first_utime + period);
  }
  void Sent(int64_t utime) {
    const auto it = index_.find(utime);
    if (it != index_.end()) sent_ns_[it->second] = Clock::now().time_since_epoch().count();
  }
  void Received(const ObjectCloud& cloud) {
    if (cloud.is_final) return;
    const auto it = index_.find(cloud.utime);
    std::lock_guard<std::mutex> lock(mutex_);
    ++clouds_;
    if (it == index_.end()) return;
    const int64_t sent = sent_ns_[it->second].load();
    if (sent != 0) latency_.Add((Clock::now().time_since_epoch().count() - sent) * 1e-6);
  }
  void Status(const io::ModuleStatus& status) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (statuses_++ == 0) first_status_ = status;
    last_status_ = status;
  }
  int64_t clouds() const { std::lock_guard<std::mutex> lock(mutex_); return clouds_; }
  int64_t statuses() const { std::lock_guard<std::mutex> lock(mutex_); return statuses_; }
  rt::Percentiles latency() const { std::lock_guard<std::mutex> lock(mutex_); return latency_.Summary(); }
  io::ModuleStatus first_status() const { std::lock_guard<std::mutex> lock(mutex_); return first_status_; }
  io::ModuleStatus last_status() const { std::lock_guard<std::mutex> lock(mutex_); return last_status_; }

 private:
  std::unordered_map<int64_t, size_t> index_;
  std::vector<std::atomic<int64_t>> sent_ns_;
  mutable std::mutex mutex_;
  int64_t clouds_{0};
  int64_t statuses_{0};
  rt::SampleWindow latency_{1 << 16};
  io::ModuleStatus first_status_, last_status_;
};

void SubscribeProbe(lcm::LCM* bus, const io::ChannelNames& channels, LatencyProbe* probe) {
  bus->subscribeFunction(
      channels.object_cloud,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, LatencyProbe* p) {
        ObjectCloud cloud;
        std::string error;
        if (io::DecodeObjectCloud(rbuf->data, rbuf->data_size, &cloud, &error)) p->Received(cloud);
      },
      probe);
  bus->subscribeFunction(
      channels.status,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, LatencyProbe* p) {
        io::ModuleStatus status;
        std::string error;
        if (io::DecodeModuleStatus(rbuf->data, rbuf->data_size, &status, &error)) p->Status(status);
      },
      probe);
}

// Sleeps until `offset_us` of recording time has passed at `speed` since `start`.
void WaitForRecordingTime(Clock::time_point start, int64_t offset_us, double speed) {
  std::this_thread::sleep_until(
      start + std::chrono::microseconds(static_cast<int64_t>(static_cast<double>(offset_us) / speed)));
}

RunResult RunInProcess(const Recording& rec, const RunSpec& spec) {
  RunResult result;
  result.spec = spec;
  const int loops = spec.soak_s > 0.0
                        ? std::max(1, static_cast<int>(std::ceil(spec.soak_s / std::max(rec.duration_s(), 0.1))))
                        : 1;
  rt::LiveSessionConfig config;
  config.lcm_url = "memq://";
  config.channels = rec.channels;
  config.module.extract_every_n_frames = spec.publish_every;
  config.repair_config = rt::GripperFrameRepairConfig(repair::RepairConfig{});
  config.repair_options.incremental = spec.incremental;
  config.limits.idle_exit_s = 1.0;
  config.limits.tick_ms = 250;
  config.heap_reserve_mb = spec.heap_reserve_mb;  // process-wide: the first run's holds
  claw::ClawModel claw = claw::ClawModel::ThreeFinger();
  io::SessionDescription description;
  if (rec.session) {
    claw = MakeSessionClaw(*rec.session);
    description = *rec.session;
    if (rec.session->workspace_G) {
      config.module.pipeline.workspace.min_G = rec.session->workspace_G->min();
      config.module.pipeline.workspace.max_G = rec.session->workspace_G->max();
    }
    if (rec.session->voxel_m > 0.0) {
      config.module.pipeline.tsdf.voxel_m = rec.session->voxel_m;
      config.module.pipeline.tsdf.sdf_trunc_m = 4.0 * rec.session->voxel_m;  // live's default
    }
  } else {
    DescribeBuiltinClaw("three-finger", claw::ProceduralClawConfig{}, &description);
  }
  rt::LiveSession live(config);
  LatencyProbe probe(rec, loops);
  lcm::LCM* bus = live.publisher().lcm_instance();
  SubscribeProbe(bus, config.channels, &probe);
  live.Begin(claw, description);
  result.rss_start_mb = rt::ResidentMemoryMb();

  std::atomic<bool> receiving{true};
  std::thread receiver([&] {
    while (receiving) bus->handleTimeout(20);
  });
  const Clock::time_point start = Clock::now();
  std::atomic<double> rss_minute1{0.0};
  std::thread player([&] {
    rt::SourceEvent e;
    for (int loop = 0; loop < loops; ++loop) {
      const auto source = OpenSource(rec.path);
      for (rt::FrameResult r; (r = source->Next(&e)) != rt::FrameResult::kEndOfStream;) {
        if (r != rt::FrameResult::kOk || e.kind == rt::SourceEvent::Kind::kSession) continue;
        const int64_t shifted = LatencyProbe::Shift(rec, UtimeOf(e), loop);
        WaitForRecordingTime(start, shifted - rec.first_utime, spec.speed);
        if (e.kind == rt::SourceEvent::Kind::kDepth) {
          e.depth.utime = shifted;
          probe.Sent(shifted);
          live.OnDepth(e.depth);
          ++result.frames_sent;
        } else {
          e.gripper.utime = shifted;
          live.OnGripperState(e.gripper);
        }
        if (spec.soak_s > 0.0 && rss_minute1 == 0.0 &&
            Clock::now() - start >= std::chrono::seconds(60)) {
          rss_minute1 = rt::ResidentMemoryMb();
        }
      }
    }
  });
  player.join();
  result.play_s = MsBetween(start, Clock::now()) / 1000.0;
  live.Run(nullptr);  // returns on the idle rule, the final model out
  result.rss_end_mb = rt::ResidentMemoryMb();
  receiving = false;
  receiver.join();
  while (bus->handleTimeout(0) > 0) {
  }
  result.rss_minute1_mb = rss_minute1;
  result.last = live.Status();
  result.clouds = probe.clouds();
  result.latency = probe.latency();
  return result;
}

// The child `graspfill live` for the bus runs, its output kept for errors.
class LiveChild {
 public:
  LiveChild(const std::vector<std::string>& args, const std::string& log_path) {
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0600);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    const int rc = posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw std::runtime_error("cannot start " + args[0] + ": " + std::strerror(rc));
  }
  ~LiveChild() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  // Waits up to `timeout`; the exit status, or -1 if it had to be killed.
  int Wait(Clock::duration timeout) {
    const Clock::time_point until = Clock::now() + timeout;
    for (;;) {
      int status = 0;
      const pid_t done = waitpid(pid_, &status, WNOHANG);
      if (done == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      if (Clock::now() > until) {
        kill(pid_, SIGKILL);
        waitpid(pid_, nullptr, 0);
        pid_ = -1;
        return -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

 private:
  pid_t pid_{-1};
};

std::string ReadFile(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "r");
  if (f == nullptr) return "";
  std::string text;
  char buf[4096];
  for (size_t n; (n = std::fread(buf, 1, sizeof(buf), f)) > 0;) text.append(buf, n);
  std::fclose(f);
  return text;
}

RunResult RunAcrossProcesses(const Recording& rec, const RunSpec& spec, const std::string& url) {
  RunResult result;
  result.spec = spec;
  lcm::LCM bus(url);
  if (!bus.good()) throw std::runtime_error("cannot open LCM on " + url);
  LatencyProbe probe(rec, 1);
  SubscribeProbe(&bus, rec.channels, &probe);
  std::atomic<bool> receiving{true};
  std::thread receiver([&] {
    while (receiving) bus.handleTimeout(20);
  });

  char log_template[] = "/tmp/graspfill-bench-live-XXXXXX";
  const int log_fd = mkstemp(log_template);
  if (log_fd >= 0) close(log_fd);
  const std::string child_log = log_template;
  std::vector<std::string> args = {
      std::filesystem::read_symlink("/proc/self/exe").string(), "live", "--depth-from-lcm",
      "--lcm-url", url, "--publish-every", std::to_string(spec.publish_every), "--idle-exit-s",
      "1", "--duration-s", std::to_string(static_cast<int>(rec.duration_s() / spec.speed) + 60)};
  if (!spec.incremental) args.push_back("--no-incremental");
  args.insert(args.end(), {"--heap-reserve-mb", std::to_string(spec.heap_reserve_mb)});
  if (!rec.session) args.insert(args.end(), {"--claw", "three-finger"});
  const auto finish = [&](const std::string& note) {
    receiving = false;
    receiver.join();
    std::remove(child_log.c_str());
    result.note = note;
    return result;
  };
  auto child = std::make_unique<LiveChild>(args, child_log);

  // Until the child answers with a status, offer it the session description
  // (it starts on the first one; without one it has started with --claw).
  const io::LogEvent* session_event = nullptr;
  for (const io::LogEvent& e : rec.raw) {
    if (e.channel == rec.channels.session) {
      session_event = &e;
      break;
    }
  }
  const Clock::time_point wait_until = Clock::now() + std::chrono::seconds(30);
  while (probe.statuses() == 0 && Clock::now() < wait_until) {
    if (session_event) {
      bus.publish(session_event->channel, session_event->data.data(),
                  static_cast<unsigned>(session_event->data.size()));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  if (probe.statuses() == 0) {
    child.reset();
    const std::string out = ReadFile(child_log);
    return finish("the live process never published a status" + (out.empty() ? "" : ": " + out));
  }
  result.rss_start_mb = probe.first_status().rss_mb;

  const Clock::time_point start = Clock::now();
  int64_t first_log_us = -1;
  for (size_t i = 0; i < rec.raw.size(); ++i) {
    const io::LogEvent& e = rec.raw[i];
    if (first_log_us < 0) first_log_us = e.timestamp_us;
    WaitForRecordingTime(start, e.timestamp_us - first_log_us, spec.speed);
    if (rec.raw_depth_utime[i] != 0) {
      probe.Sent(rec.raw_depth_utime[i]);
      ++result.frames_sent;
    }
    bus.publish(e.channel, e.data.data(), static_cast<unsigned>(e.data.size()));
  }
  result.play_s = MsBetween(start, Clock::now()) / 1000.0;
  const int rc = child->Wait(std::chrono::seconds(120));
  child.reset();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the last messages in
  const std::string out = ReadFile(child_log);
  if (rc != 0) return finish("the live process exited with " + std::to_string(rc) + ": " + out);
  result.last = probe.last_status();
  result.rss_end_mb = result.last.rss_mb;
  result.clouds = probe.clouds();
  result.latency = probe.latency();
  return finish("");
}

nlohmann::ordered_json ToJson(const RunResult& r) {
  nlohmann::ordered_json j;
  j["speed"] = r.spec.speed;
  j["transport"] = r.spec.transport;
  j["repair"] = r.spec.incremental ? "incremental" : "full";
  if (!r.note.empty()) {
    j["skipped"] = r.note;
    return j;
  }
  j["frames_in"] = r.last.frames_in;
  j["frames_used"] = r.last.frames_used;
  j["frames_dropped"] = r.last.frames_dropped;
  j["clouds"] = r.clouds;
  j["cloud_hz"] = r.play_s > 0 ? r.clouds / r.play_s : 0.0;
  j["latency_ms"] = {{"p50", r.latency.p50}, {"p95", r.latency.p95}, {"p99", r.latency.p99},
                     {"max", r.latency.max}};
  j["module_latency_ms"] = {{"p50", r.last.latency_ms_p50}, {"p99", r.last.latency_ms_p99},
                            {"max", r.last.latency_ms_max}};
  j["update_ms"] = {{"p50", r.last.update_ms_p50}, {"p99", r.last.update_ms_p99}};
  j["full_repair_ms"] = {{"p50", r.last.full_repair_ms_p50}, {"p99", r.last.full_repair_ms_p99}};
  j["rss_mb"] = {{"start", r.rss_start_mb}, {"end", r.rss_end_mb}};
  if (r.spec.soak_s > 0.0) {
    j["soak_s"] = r.play_s;
    j["rss_mb"]["minute_1"] = r.rss_minute1_mb;
  }
  return j;
}

void PrintRow(const RunResult& r) {
  const char* repair = r.spec.incremental ? "incremental" : "full";
  if (!r.note.empty()) {
    std::printf("%-5s %4.1fx %-11s  skipped: %s\n", r.spec.transport.c_str(), r.spec.speed, repair,
                r.note.c_str());
    return;
  }
  std::printf("%-5s %4.1fx %-11s %5lld %5lld %5lld  %4lld %5.1f  %7.1f %7.1f %7.1f %7.1f  %6.1f %6.1f  "
              "%6.0f %6.0f  %6.1f -> %6.1f\n",
              r.spec.transport.c_str(), r.spec.speed, repair,
              static_cast<long long>(r.last.frames_in), static_cast<long long>(r.last.frames_used),
              static_cast<long long>(r.last.frames_dropped), static_cast<long long>(r.clouds),
              r.play_s > 0 ? r.clouds / r.play_s : 0.0, r.latency.p50, r.latency.p95, r.latency.p99,
              r.latency.max, r.last.update_ms_p50, r.last.update_ms_p99, r.last.full_repair_ms_p50,
              r.last.full_repair_ms_p99, r.rss_start_mb, r.rss_end_mb);
  if (r.spec.soak_s > 0.0) {
    std::printf("  soak %.0f s: RSS %.1f MB at minute 1, %.1f MB at the end (%+.1f%%)\n", r.play_s,
                r.rss_minute1_mb, r.rss_end_mb,
                r.rss_minute1_mb > 0 ? 100.0 * (r.rss_end_mb - r.rss_minute1_mb) / r.rss_minute1_mb : 0.0);
  }
  std::fflush(stdout);
}

std::vector<double> ParseSpeeds(const std::string& text) {
  std::vector<double> speeds;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    speeds.push_back(ParseDouble("--speeds", item, 0.1, 100.0));
  }
  if (speeds.empty()) throw UsageError("--speeds needs at least one speed, e.g. 1,2,4");
  return speeds;
}

}  // namespace

int RunBenchLive(const Args& args) {
  std::string log = (BundledRecordingDir() / "recording.lcmlog").string();
  std::vector<double> speeds = {1.0, 2.0, 4.0};
  std::string transport = "both", repair = "both";
  int publish_every = 3;
  double soak_s = 0.0;
  int heap_reserve_mb = kLiveHeapReserveMb;
  bool json = false;
  try {
    bool log_given = false;
    for (size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      const bool has_value = i + 1 < args.size();
      if (a == "--help" || a == "-h") {
        std::fputs(Usage().c_str(), stdout);
        return 0;
      } else if (a == "--json") {
        json = true;
      } else if (a == "--speeds" && has_value) {
        speeds = ParseSpeeds(args[++i]);
      } else if (a == "--transport" && has_value) {
        transport = args[++i];
        if (transport != "memq" && transport != "udpm" && transport != "both") {
          throw UsageError("--transport must be memq, udpm or both, not '" + transport + "'");
        }
      } else if (a == "--repair" && has_value) {
        repair = args[++i];
        if (repair != "incremental" && repair != "full" && repair != "both") {
          throw UsageError("--repair must be incremental, full or both, not '" + repair + "'");
        }
      } else if (a == "--publish-every" && has_value) {
        publish_every = ParseInteger<int>("--publish-every", args[++i], 1, 1000);
      } else if (a == "--soak-s" && has_value) {
        soak_s = ParseDouble("--soak-s", args[++i], 60.0, 86400.0);
      } else if (a == "--heap-reserve-mb" && has_value) {
        heap_reserve_mb = ParseInteger<int>("--heap-reserve-mb", args[++i], 0, 65536);
      } else if (!a.empty() && a[0] != '-' && !log_given) {
        log = a;
        log_given = true;
      } else {
        throw UsageError("unknown or incomplete option '" + a + "'");
      }
    }
  } catch (const UsageError& e) {
    std::fprintf(stderr, "graspfill bench live: %s\n%s", e.what(), Usage().c_str());
    return 2;
  }

  // The namespace first, while this is the only thread (unshare moves the
  // calling thread only).
  std::string no_bus;
  if (transport != "memq") no_bus = EnterPrivateNetwork();
  const std::string url = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608";

  Recording rec;
  try {
    rec = LoadRecording(log);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill bench live: %s\n", ErrorText(e).c_str());
    return 1;
  }
  if (!json) {
    std::printf("bench live: %s, %d depth frames over %.1f s, a cloud every %d fused frames, "
                "heap reserve %d MB%s\n",
                log.c_str(), rec.depth_frames, rec.duration_s(), publish_every, heap_reserve_mb,
                rec.session ? "" : " (no session description: three-finger claw)");
    std::printf("latency: a frame's send -> the receipt of the first cloud it is the newest frame of "
                "[ms]; update/full: the repair's times [ms]\n");
    std::printf("%-5s %5s %-11s %5s %5s %5s  %4s %5s  %7s %7s %7s %7s  %6s %6s  %6s %6s  %s\n",
                "bus", "speed", "repair", "in", "used", "drop", "clds", "Hz", "lat50", "lat95",
                "lat99", "latmax", "upd50", "upd99", "full50", "full99", "RSS MB");
    std::fflush(stdout);
  }
  std::vector<RunResult> results;
  std::vector<bool> modes;
  if (repair != "full") modes.push_back(true);
  if (repair != "incremental") modes.push_back(false);
  try {
    for (const std::string bus : {"memq", "udpm"}) {
      if (transport != "both" && transport != bus) continue;
      for (const double speed : speeds) {
        for (const bool incremental : modes) {
          RunSpec spec{bus, speed, incremental, publish_every, 0.0, heap_reserve_mb};
          RunResult r;
          if (bus == std::string("memq")) {
            r = RunInProcess(rec, spec);
          } else if (!no_bus.empty()) {
            r.spec = spec;
            r.note = "no private network namespace for multicast (" + no_bus + ")";
          } else {
            r = RunAcrossProcesses(rec, spec, url);
          }
          if (!json) PrintRow(r);
          results.push_back(r);
        }
      }
    }
    if (soak_s > 0.0) {
      RunResult r = RunInProcess(
          rec, RunSpec{"memq", 1.0, repair != "full", publish_every, soak_s, heap_reserve_mb});
      if (!json) PrintRow(r);
      results.push_back(r);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill bench live: %s\n", ErrorText(e).c_str());
    return 1;
  }
  if (json) {
    nlohmann::ordered_json j;
    j["recording"] = log;
    j["depth_frames"] = rec.depth_frames;
    j["publish_every"] = publish_every;
    j["heap_reserve_mb"] = heap_reserve_mb;
    j["runs"] = nlohmann::ordered_json::array();
    for (const RunResult& r : results) j["runs"].push_back(ToJson(r));
    std::printf("%s\n", j.dump(2).c_str());
  }
  return 0;
}

}  // namespace graspfill::cli
