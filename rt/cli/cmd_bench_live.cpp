// SPDX-License-Identifier: BSD-3-Clause
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
//
// The fault soak (--soak-faults, issue 36): the recording played in a loop
// into a `graspfill live` process over the bus, once clean (the reference)
// and once with malformed messages of every kind among the valid ones
// (bench_live_faults.hpp). The process must live to the end, count every
// malformed message under its reason, hold its RSS near the clean run's and
// keep publishing clouds throughout.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <limits>
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

#include "bench_live_faults.hpp"
#include "claw_option.hpp"
#include "commands.hpp"
#include "data_paths.hpp"
#include "error_text.hpp"
#include "graspfill/io/cloud_chunks.hpp"
#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/io/messages.hpp"
#include "module/cloud_repair.hpp"
#include "module/live_session.hpp"
#include "module/process_memory.hpp"
#include "module/sample_window.hpp"
#include "number_parsing.hpp"
#include "option_walk.hpp"
#include "private_network.hpp"
#include "sources/lcm_log_source.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {
namespace {

using Clock = std::chrono::steady_clock;

std::string LiveBenchUsage() {
  return "usage: graspfill bench live [LOG] [--speeds 1,2,4] [--transport memq|udpm|both]\n"
         "                            [--repair incremental|full|both] [--publish-every N]\n"
         "                            [--soak-s S [--soak-faults PERCENT] [--soak-speed X]]\n"
         "                            [--heap-reserve-mb N] [--json]\n"
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
         "  --soak-faults P    the soak across processes instead (udpm, as above), twice: clean,\n"
         "                     then with P% (0 < P <= 50) malformed messages of every kind among\n"
         "                     the valid ones; reports whether `live` lived to the end, its\n"
         "                     rejects by reason against those sent, RSS against the clean run's\n"
         "                     and the clouds of every minute (of every tenth when S < 600)\n"
         "  --soak-speed X     the fault soak's playback speed (default 4)\n"
         "  --heap-reserve-mb N `graspfill live`'s --heap-reserve-mb, in-process and in the child\n"
         "                     (default " +
         std::to_string(kLiveHeapReserveMb) + "; 0: the allocator's defaults)\n";
}

double MsBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// The recording: read from the file as it plays in-process (as a replay
// does: holding 900 decoded frames would take GBs), raw in memory for the bus.
struct Recording {
  std::string path;
  std::optional<io::SessionDescription> session;
  std::vector<int64_t> depth_utimes;     // in log order
  std::vector<io::LogEvent> raw;         // every event of our channels, in log order
  std::vector<int64_t> raw_depth_utime;  // beside raw: a depth frame's utime, else 0
  io::ChannelNames channels;
  int depth_frames{0};
  int64_t first_utime{0}, last_utime{0};  // of the depth frames
  // A loop's span: from the first to the last event's utime (gripper states
  // may begin before and end after the frames), plus a frame period.
  int64_t loop_span_us{0};
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
  int64_t min_utime = std::numeric_limits<int64_t>::max(), max_utime = 0;
  for (rt::FrameResult r; (r = source->Next(&event)) != rt::FrameResult::kEndOfStream;) {
    if (r != rt::FrameResult::kOk) continue;  // counted by replay; a benchmark plays the rest
    if (event.kind != rt::SourceEvent::Kind::kSession) {
      min_utime = std::min(min_utime, UtimeOf(event));
      max_utime = std::max(max_utime, UtimeOf(event));
    }
    if (event.kind == rt::SourceEvent::Kind::kSession) {
      if (!rec.session) rec.session = event.session;
    } else if (event.kind == rt::SourceEvent::Kind::kDepth) {
      if (rec.depth_frames++ == 0) rec.first_utime = event.depth.utime;
      rec.last_utime = std::max(rec.last_utime, event.depth.utime);
      rec.depth_utimes.push_back(event.depth.utime);
    }
  }
  if (rec.depth_frames < 2) throw std::runtime_error("'" + path + "' has fewer than 2 depth frames");
  rec.loop_span_us = max_utime - min_utime + (rec.last_utime - rec.first_utime) / (rec.depth_frames - 1);
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
  double fault_percent{0.0};  // the fault soak's malformed messages (udpm)
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
  std::string note;            // why the run did not happen, if it did not
  // The fault soak (udpm soaks): `live` alive when the play ended, malformed
  // messages sent by reason, its highest RSS, clouds in each window.
  bool live_alive_at_end{false};
  std::array<int64_t, io::BadMessageCounts::kNumReasons> malformed_sent{};
  double rss_peak_mb{0.0};
  double window_s{0.0};
  std::vector<int64_t> clouds_per_window;
};

// When each depth frame went out (by utime), and the clouds that came back.
class LatencyProbe {
 public:
  // Joins a udpm publisher's object_cloud_chunk_t slices (the bus's thread).
  io::CloudChunkAssembler cloud_slices;
  explicit LatencyProbe(const Recording& rec, int loops) {
    for (int loop = 0; loop < loops; ++loop) {
      for (const int64_t utime : rec.depth_utimes) index_.emplace(Shift(rec, utime, loop), index_.size());
    }
    sent_ns_ = std::vector<std::atomic<int64_t>>(index_.size());
  }
  static int64_t Shift(const Recording& rec, int64_t utime, int loop) {
    // One loop after another, a frame period apart: no clock ever goes back.
    return utime + loop * rec.loop_span_us;
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
    if (window_s_ > 0.0) {
      const auto window = static_cast<size_t>(
          std::chrono::duration<double>(Clock::now() - windows_start_).count() / window_s_);
      if (window >= clouds_per_window_.size()) clouds_per_window_.resize(window + 1, 0);
      ++clouds_per_window_[window];
    }
    if (it == index_.end()) return;
    const int64_t sent = sent_ns_[it->second].load();
    if (sent != 0) latency_.Add((Clock::now().time_since_epoch().count() - sent) * 1e-6);
  }
  void Status(const io::ModuleStatus& status) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (statuses_++ == 0) first_status_ = status;
    last_status_ = status;
    rss_peak_mb_ = std::max(rss_peak_mb_, status.rss_mb);
  }
  // From now on, count the clouds received in windows of `window_s`.
  void CountCloudsInWindows(double window_s) {
    std::lock_guard<std::mutex> lock(mutex_);
    window_s_ = window_s;
    windows_start_ = Clock::now();
  }
  std::vector<int64_t> clouds_per_window() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return clouds_per_window_;
  }
  double rss_peak_mb() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return rss_peak_mb_;
  }
  int64_t clouds() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return clouds_;
  }
  int64_t statuses() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return statuses_;
  }
  rt::Percentiles latency() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return latency_.Summary();
  }
  io::ModuleStatus first_status() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return first_status_;
  }
  io::ModuleStatus last_status() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_status_;
  }

 private:
  std::unordered_map<int64_t, size_t> index_;
  std::vector<std::atomic<int64_t>> sent_ns_;
  mutable std::mutex mutex_;
  int64_t clouds_{0};
  int64_t statuses_{0};
  rt::SampleWindow latency_{1 << 16};
  io::ModuleStatus first_status_, last_status_;
  double rss_peak_mb_{0.0};
  double window_s_{0.0};
  Clock::time_point windows_start_;
  std::vector<int64_t> clouds_per_window_;
};

void SubscribeProbe(lcm::LCM* bus, const io::ChannelNames& channels, LatencyProbe* probe) {
  bus->subscribeFunction(
      channels.object_cloud,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, LatencyProbe* p) {
        ObjectCloud cloud;
        std::string error;
        if (p->cloud_slices.Add(rbuf->data, rbuf->data_size, &error) !=
            io::CloudChunkAssembler::Result::kComplete) {
          return;
        }
        const std::vector<uint8_t>& bytes = p->cloud_slices.cloud();
        if (io::DecodeObjectCloud(bytes.data(), bytes.size(), &cloud, &error)) p->Received(cloud);
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

// The windows a soak counts clouds in: minutes, or tenths of a shorter one.
double SoakWindowS(const RunSpec& spec) { return spec.soak_s >= 600.0 ? 60.0 : spec.soak_s / 10.0; }

// How many times a run plays the recording: once, or a soak's length.
int LoopsOf(const Recording& rec, const RunSpec& spec) {
  if (spec.soak_s <= 0.0) return 1;
  const double loop_s = std::max(rec.loop_span_us * 1e-6, 0.1);
  return std::max(1, static_cast<int>(std::ceil(spec.soak_s * spec.speed / loop_s)));
}

RunResult RunInProcess(const Recording& rec, const RunSpec& spec) {
  RunResult result;
  result.spec = spec;
  const int loops = LoopsOf(rec, spec);
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
        if (spec.soak_s > 0.0 && rss_minute1 == 0.0 && Clock::now() - start >= std::chrono::seconds(60)) {
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
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0600);
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
  bool Running() {
    if (pid_ <= 0) return false;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) != pid_) return true;
    exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    pid_ = -1;
    return false;
  }
  // Waits up to `timeout`; the exit status, or -1 if it had to be killed.
  int Wait(Clock::duration timeout) {
    if (pid_ <= 0) return exit_status_;
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
  int exit_status_{-1};
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

// The command line of the `live` child: the bus, the run's settings, and a
// duration that outlasts the play.
std::vector<std::string> LiveChildArgs(const Recording& rec, const RunSpec& spec, const std::string& url,
                                       int loops) {
  std::vector<std::string> args = {
      std::filesystem::read_symlink("/proc/self/exe").string(), "live", "--depth-from-lcm", "--lcm-url", url,
      "--publish-every", std::to_string(spec.publish_every), "--idle-exit-s",
      // A soak outlasts the stalls of a loaded machine (seconds): `live`
      // must not end the session on one, as it rightly does after 1 s idle.
      spec.soak_s > 0.0 ? "10" : "1", "--duration-s",
      std::to_string(static_cast<int>(loops * rec.loop_span_us * 1e-6 / spec.speed) + 60)};
  if (!spec.incremental) args.push_back("--no-incremental");
  args.insert(args.end(), {"--heap-reserve-mb", std::to_string(spec.heap_reserve_mb)});
  if (!rec.session) args.insert(args.end(), {"--claw", "three-finger"});
  return args;
}

// Until the child answers with a status (30 s at most), offers it the
// session description (it starts on the first one; without one it has
// started with --claw). False when no status came.
bool WaitForFirstStatus(const Recording& rec, const LatencyProbe& probe, lcm::LCM* bus) {
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
      bus->publish(session_event->channel, session_event->data.data(),
                   static_cast<unsigned>(session_event->data.size()));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  return probe.statuses() > 0;
}

// The malformed messages of a faults run, made from the recording's first
// depth image and gripper state; a note instead when it cannot be.
std::string MakeMalformed(const Recording& rec, std::optional<MalformedMessages>* malformed) {
  const std::vector<uint8_t>* depth = nullptr;
  const std::vector<uint8_t>* gripper = nullptr;
  for (size_t i = 0; i < rec.raw.size(); ++i) {
    if (!depth && rec.raw_depth_utime[i] != 0) depth = &rec.raw[i].data;
    if (!gripper && rec.raw[i].channel == rec.channels.gripper_state) gripper = &rec.raw[i].data;
  }
  if (!depth || !gripper) return "the recording has no gripper state to break";
  try {
    malformed->emplace(rec.channels, *depth, *gripper);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// Publishes the recording `loops` times at the run's speed, each loop a
// recording's span later, with the faults run's malformed messages among
// them; stops early when the child has ended.
void PlayLoops(const Recording& rec, const RunSpec& spec, int loops, LiveChild* child,
               MalformedMessages* malformed, lcm::LCM* bus, LatencyProbe* probe, RunResult* result) {
  const Clock::time_point start = Clock::now();
  const int64_t first_log_us = rec.raw.empty() ? 0 : rec.raw.front().timestamp_us;
  double malformed_owed = 0.0;
  std::vector<uint8_t> shifted;
  for (int loop = 0; loop < loops; ++loop) {
    // Each loop a recording's span later, in utime and in log time alike.
    const int64_t offset_us = LatencyProbe::Shift(rec, 0, loop);
    if (loop > 0 && !child->Running()) break;
    for (size_t i = 0; i < rec.raw.size(); ++i) {
      const io::LogEvent& e = rec.raw[i];
      if (loop > 0 && e.channel == rec.channels.session) continue;  // the session is described once
      WaitForRecordingTime(start, e.timestamp_us - first_log_us + offset_us, spec.speed);
      const std::vector<uint8_t>* data = &e.data;
      if (loop > 0) {
        shifted = e.data;
        ShiftEncodedUtime(&shifted, offset_us);
        data = &shifted;
      }
      if (rec.raw_depth_utime[i] != 0) {
        probe->Sent(rec.raw_depth_utime[i] + offset_us);
        ++result->frames_sent;
      }
      bus->publish(e.channel, data->data(), static_cast<unsigned>(data->size()));
      if (!malformed) continue;
      for (malformed_owed += spec.fault_percent / 100.0; malformed_owed >= 1.0; malformed_owed -= 1.0) {
        const MalformedMessage& m = malformed->Next();
        bus->publish(m.channel, m.data.data(), static_cast<unsigned>(m.data.size()));
        ++result->malformed_sent[static_cast<size_t>(m.reason)];
      }
    }
  }
  result->live_alive_at_end = child->Running();
  result->play_s = MsBetween(start, Clock::now()) / 1000.0;
}

// What the probe saw of the run: the last status, memory, clouds, latency
// and (soak) the clouds per window of the play.
void TakeProbeResults(const RunSpec& spec, const LatencyProbe& probe, RunResult* result) {
  result->last = probe.last_status();
  result->rss_end_mb = result->last.rss_mb;
  result->rss_peak_mb = probe.rss_peak_mb();
  result->clouds = probe.clouds();
  result->latency = probe.latency();
  if (spec.soak_s > 0.0) {
    result->window_s = SoakWindowS(spec);
    result->clouds_per_window = probe.clouds_per_window();
    // Windows that ended before the play did and received nothing count as 0.
    const auto played = static_cast<size_t>(result->play_s / result->window_s);
    if (result->clouds_per_window.size() < played) result->clouds_per_window.resize(played, 0);
    result->clouds_per_window.resize(std::min(result->clouds_per_window.size(), played));
  }
}

RunResult RunAcrossProcesses(const Recording& rec, const RunSpec& spec, const std::string& url) {
  RunResult result;
  result.spec = spec;
  lcm::LCM bus(url);
  if (!bus.good()) throw std::runtime_error("cannot open LCM on " + url);
  const int loops = LoopsOf(rec, spec);
  LatencyProbe probe(rec, loops);
  SubscribeProbe(&bus, rec.channels, &probe);
  std::atomic<bool> receiving{true};
  std::thread receiver([&] {
    while (receiving) bus.handleTimeout(20);
  });

  char log_template[] = "/tmp/graspfill-bench-live-XXXXXX";
  const int log_fd = mkstemp(log_template);
  if (log_fd >= 0) close(log_fd);
  const std::string child_log = log_template;
  const auto finish = [&](const std::string& note) {
    receiving = false;
    receiver.join();
    std::remove(child_log.c_str());
    result.note = note;
    return result;
  };
  std::unique_ptr<LiveChild> child;
  try {
    child = std::make_unique<LiveChild>(LiveChildArgs(rec, spec, url, loops), child_log);
  } catch (const std::exception& e) {
    return finish(e.what());
  }
  if (!WaitForFirstStatus(rec, probe, &bus)) {
    child.reset();
    const std::string out = ReadFile(child_log);
    return finish("the live process never published a status" + (out.empty() ? "" : ": " + out));
  }
  result.rss_start_mb = probe.first_status().rss_mb;

  std::optional<MalformedMessages> malformed;
  if (spec.fault_percent > 0.0) {
    if (const std::string note = MakeMalformed(rec, &malformed); !note.empty()) return finish(note);
  }
  if (spec.soak_s > 0.0) probe.CountCloudsInWindows(SoakWindowS(spec));
  PlayLoops(rec, spec, loops, child.get(), malformed ? &*malformed : nullptr, &bus, &probe, &result);
  const int rc = child->Wait(std::chrono::seconds(120));
  child.reset();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the last messages in
  const std::string out = ReadFile(child_log);
  if (rc != 0) return finish("the live process exited with " + std::to_string(rc) + ": " + out);
  TakeProbeResults(spec, probe, &result);
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
  j["frames_sent"] = r.frames_sent;
  j["frames_in"] = r.last.frames_in;
  j["frames_used"] = r.last.frames_used;
  j["frames_dropped"] = r.last.frames_dropped;
  j["clouds"] = r.clouds;
  j["cloud_hz"] = r.play_s > 0 ? r.clouds / r.play_s : 0.0;
  j["latency_ms"] = {
      {"p50", r.latency.p50}, {"p95", r.latency.p95}, {"p99", r.latency.p99}, {"max", r.latency.max}};
  j["module_latency_ms"] = {
      {"p50", r.last.latency_ms_p50}, {"p99", r.last.latency_ms_p99}, {"max", r.last.latency_ms_max}};
  j["update_ms"] = {{"p50", r.last.update_ms_p50}, {"p99", r.last.update_ms_p99}};
  j["full_repair_ms"] = {{"p50", r.last.full_repair_ms_p50}, {"p99", r.last.full_repair_ms_p99}};
  j["rss_mb"] = {{"start", r.rss_start_mb}, {"end", r.rss_end_mb}};
  if (r.spec.soak_s > 0.0 && r.spec.transport == "memq") {
    j["soak_s"] = r.play_s;
    j["rss_mb"]["minute_1"] = r.rss_minute1_mb;
  } else if (r.spec.soak_s > 0.0) {
    j["soak_s"] = r.play_s;
    j["fault_percent"] = r.spec.fault_percent;
    j["live_alive_at_end"] = r.live_alive_at_end;
    j["rss_mb"]["peak"] = r.rss_peak_mb;
    j["window_s"] = r.window_s;
    j["clouds_per_window"] = r.clouds_per_window;
    nlohmann::ordered_json sent = nlohmann::ordered_json::object(), counted = sent;
    int64_t sent_total = 0;
    for (size_t i = 1; i < io::BadMessageCounts::kNumReasons; ++i) {
      const auto reason = static_cast<io::MessageError>(i);
      sent_total += r.malformed_sent[i];
      if (r.malformed_sent[i] > 0) sent[io::MessageErrorName(reason)] = r.malformed_sent[i];
      if (r.last.bad_messages[reason] > 0)
        counted[io::MessageErrorName(reason)] = r.last.bad_messages[reason];
    }
    j["malformed_sent"] = sent_total;
    j["rejects_counted"] = r.last.decode_errors;
    j["malformed_sent_by_reason"] = sent;
    j["rejects_counted_by_reason"] = counted;
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
  std::printf(
      "%-5s %4.1fx %-11s %5lld %5lld %5lld  %4lld %5.1f  %7.1f %7.1f %7.1f %7.1f  %6.1f %6.1f  "
      "%6.0f %6.0f  %6.1f -> %6.1f\n",
      r.spec.transport.c_str(), r.spec.speed, repair, static_cast<long long>(r.last.frames_in),
      static_cast<long long>(r.last.frames_used), static_cast<long long>(r.last.frames_dropped),
      static_cast<long long>(r.clouds), r.play_s > 0 ? r.clouds / r.play_s : 0.0, r.latency.p50,
      r.latency.p95, r.latency.p99, r.latency.max, r.last.update_ms_p50, r.last.update_ms_p99,
      r.last.full_repair_ms_p50, r.last.full_repair_ms_p99, r.rss_start_mb, r.rss_end_mb);
  if (r.spec.soak_s > 0.0 && r.spec.transport != "memq") {
    int64_t sent = 0, counted_as_sent = 0;
    for (size_t i = 1; i < io::BadMessageCounts::kNumReasons; ++i) {
      sent += r.malformed_sent[i];
      counted_as_sent += std::min(r.malformed_sent[i], r.last.bad_messages.by_reason[i]);
    }
    int64_t fewest = r.clouds_per_window.empty() ? 0 : r.clouds_per_window.front();
    for (const int64_t n : r.clouds_per_window) fewest = std::min(fewest, n);
    // A valid frame the module never received was lost on the way (a full
    // socket buffer): malformed messages may have been too.
    std::printf(
        "  soak %.0f s, %.1f%% malformed: live %s at the end; malformed sent %lld, rejects "
        "counted %lld (%lld under the reason sent); valid frames lost on the way %lld; RSS "
        "peak %.1f MB, end %.1f MB; clouds per %.0f s: fewest %lld of %zu windows\n",
        r.play_s, r.spec.fault_percent, r.live_alive_at_end ? "alive" : "NOT alive",
        static_cast<long long>(sent), static_cast<long long>(r.last.decode_errors),
        static_cast<long long>(counted_as_sent), static_cast<long long>(r.frames_sent - r.last.frames_in),
        r.rss_peak_mb, r.rss_end_mb, r.window_s, static_cast<long long>(fewest), r.clouds_per_window.size());
  } else if (r.spec.soak_s > 0.0) {
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

struct BenchLiveOptions {
  std::string log = (BundledRecordingDir() / "recording.lcmlog").string();
  std::vector<double> speeds = {1.0, 2.0, 4.0};
  std::string transport = "both";
  std::string repair = "both";
  int publish_every = 3;
  double soak_s = 0.0;
  double soak_faults = 0.0;
  double soak_speed = 4.0;
  int heap_reserve_mb = kLiveHeapReserveMb;
  bool json = false;
  bool help = false;
};

// The command line, up to --help if given.
// @throws UsageError on an unknown option, a missing or bad value.
BenchLiveOptions ParseBenchLiveArgs(const Args& args) {
  BenchLiveOptions o;
  bool log_given = false;
  o.help = ForEachOption(args, [&](const std::string& a, bool has_value, size_t* i) {
    if (a == "--json") {
      o.json = true;
    } else if (a == "--speeds" && has_value) {
      o.speeds = ParseSpeeds(args[++*i]);
    } else if (a == "--transport" && has_value) {
      o.transport = args[++*i];
      if (o.transport != "memq" && o.transport != "udpm" && o.transport != "both") {
        throw UsageError("--transport must be memq, udpm or both, not '" + o.transport + "'");
      }
    } else if (a == "--repair" && has_value) {
      o.repair = args[++*i];
      if (o.repair != "incremental" && o.repair != "full" && o.repair != "both") {
        throw UsageError("--repair must be incremental, full or both, not '" + o.repair + "'");
      }
    } else if (a == "--publish-every" && has_value) {
      o.publish_every = ParseInteger<int>("--publish-every", args[++*i], 1, 1000);
    } else if (a == "--soak-s" && has_value) {
      o.soak_s = ParseDouble("--soak-s", args[++*i], 10.0, 86400.0);
    } else if (a == "--soak-faults" && has_value) {
      o.soak_faults = ParseDouble("--soak-faults", args[++*i], 0.001, 50.0);
    } else if (a == "--soak-speed" && has_value) {
      o.soak_speed = ParseDouble("--soak-speed", args[++*i], 0.1, 100.0);
    } else if (a == "--heap-reserve-mb" && has_value) {
      o.heap_reserve_mb = ParseInteger<int>("--heap-reserve-mb", args[++*i], 0, 65536);
    } else if (!a.empty() && a[0] != '-' && !log_given) {
      o.log = a;
      log_given = true;
    } else {
      throw UsageError(BadOptionText(a, LiveBenchUsage()) + " (or its value is missing)");
    }
  });
  if (o.help) return o;
  if (o.soak_s > 0.0 && o.soak_s < 60.0 && o.soak_faults == 0.0) {
    throw UsageError("--soak-s must be >= 60 (RSS at minute 1), or come with --soak-faults");
  }
  if (o.soak_faults > 0.0 && o.soak_s == 0.0) throw UsageError("--soak-faults needs --soak-s");
  return o;
}

void PrintTableHeader(const BenchLiveOptions& o, const Recording& rec) {
  std::printf(
      "bench live: %s, %d depth frames over %.1f s, a cloud every %d fused frames, "
      "heap reserve %d MB%s\n",
      o.log.c_str(), rec.depth_frames, rec.duration_s(), o.publish_every, o.heap_reserve_mb,
      rec.session ? "" : " (no session description: three-finger claw)");
  std::printf(
      "latency: a frame's send -> the receipt of the first cloud it is the newest frame of "
      "[ms]; update/full: the repair's times [ms]\n");
  std::printf("%-5s %5s %-11s %5s %5s %5s  %4s %5s  %7s %7s %7s %7s  %6s %6s  %6s %6s  %s\n", "bus", "speed",
              "repair", "in", "used", "drop", "clds", "Hz", "lat50", "lat95", "lat99", "latmax", "upd50",
              "upd99", "full50", "full99", "RSS MB");
  std::fflush(stdout);
}

// Every run the options ask for, in order: each transport at each speed in
// each repair mode, then the soak, then the faults soak without and with
// its malformed messages.
std::vector<RunSpec> RunSpecs(const BenchLiveOptions& o) {
  std::vector<bool> modes;
  if (o.repair != "full") modes.push_back(true);
  if (o.repair != "incremental") modes.push_back(false);
  std::vector<RunSpec> specs;
  for (const std::string bus : {"memq", "udpm"}) {
    if (o.transport != "both" && o.transport != bus) continue;
    for (const double speed : o.speeds) {
      for (const bool incremental : modes) {
        specs.push_back(RunSpec{bus, speed, incremental, o.publish_every, 0.0, o.heap_reserve_mb});
      }
    }
  }
  if (o.soak_s > 0.0 && o.soak_faults == 0.0) {
    specs.push_back(RunSpec{"memq", 1.0, o.repair != "full", o.publish_every, o.soak_s, o.heap_reserve_mb});
  }
  for (const double percent : {0.0, o.soak_faults}) {
    if (o.soak_faults == 0.0) break;
    specs.push_back(RunSpec{"udpm", o.soak_speed, o.repair != "full", o.publish_every, o.soak_s,
                            o.heap_reserve_mb, percent});
  }
  return specs;
}

void PrintBenchLiveJson(const BenchLiveOptions& o, const Recording& rec,
                        const std::vector<RunResult>& results) {
  nlohmann::ordered_json j;
  j["recording"] = o.log;
  j["depth_frames"] = rec.depth_frames;
  j["publish_every"] = o.publish_every;
  j["heap_reserve_mb"] = o.heap_reserve_mb;
  j["runs"] = nlohmann::ordered_json::array();
  for (const RunResult& r : results) j["runs"].push_back(ToJson(r));
  std::printf("%s\n", j.dump(2).c_str());
}

}  // namespace

int RunBenchLive(const Args& args) {
  BenchLiveOptions o;
  try {
    o = ParseBenchLiveArgs(args);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "graspfill bench live: %s\n%s", e.what(), LiveBenchUsage().c_str());
    return 2;
  }
  if (o.help) {
    std::fputs(LiveBenchUsage().c_str(), stdout);
    return 0;
  }

  // The namespace first, while this is the only thread (unshare moves the
  // calling thread only).
  std::string no_bus;
  if (o.transport != "memq" || o.soak_faults > 0.0) no_bus = EnterPrivateNetwork();
  const std::string url = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608";

  Recording rec;
  try {
    rec = LoadRecording(o.log);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill bench live: %s\n", ErrorText(e).c_str());
    return 1;
  }
  if (!o.json) PrintTableHeader(o, rec);
  std::vector<RunResult> results;
  try {
    for (const RunSpec& spec : RunSpecs(o)) {
      RunResult r;
      if (spec.transport == "memq") {
        r = RunInProcess(rec, spec);
      } else if (!no_bus.empty()) {
        r.spec = spec;
        r.note = "no private network namespace for multicast (" + no_bus + ")";
      } else {
        r = RunAcrossProcesses(rec, spec, url);
      }
      if (!o.json) PrintRow(r);
      results.push_back(r);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill bench live: %s\n", ErrorText(e).c_str());
    return 1;
  }
  if (o.json) PrintBenchLiveJson(o, rec, results);
  return 0;
}

}  // namespace graspfill::cli
