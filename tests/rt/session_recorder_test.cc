// SPDX-License-Identifier: BSD-3-Clause
// The session recorder (issue 36): its queue bounded in bytes under many
// large frames, and a full disk that stops the recording but keeps the log.
#include "sinks/session_recorder.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <thread>

#include "../io/file_size_limit.hpp"
#include "module/process_memory.hpp"
#include "sources/lcm_log_source.hpp"

namespace graspfill::rt {
namespace {

namespace fs = std::filesystem;
constexpr int64_t kMiB = int64_t{1} << 20;

std::string ScratchPath(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::path(GRASPFILL_BINARY_DIR) / "test_tmp" / "rt_session_recorder" / info->name();
  fs::remove_all(dir);
  fs::create_directories(dir);
  return (dir / name).string();
}

io::SessionDescription Session() {
  io::SessionDescription session;
  session.claw_name = "three-finger";
  session.claw_text = "{}";
  return session;
}

// Noisy depth (0.4-0.9 m): zlib cannot shrink it much, so the writer is
// slower than Record() and the queue fills.
DepthFrame NoisyFrame(int width, int height) {
  DepthFrame frame;
  frame.intrinsics = {width, height, 500.0, 500.0, width / 2.0, height / 2.0};
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> depth_m(0.4f, 0.9f);
  frame.depth_m.resize(static_cast<size_t>(width) * height);
  for (float& d : frame.depth_m) d = depth_m(rng);
  return frame;
}

struct ReadBack {
  int64_t events{0};
  int64_t depth{0};
  bool truncated{false};
};
ReadBack ReadAll(const std::string& path) {
  LcmLogSource::Config config;
  config.path = path;
  config.session_events = true;
  LcmLogSource source(config);
  ReadBack back;
  SourceEvent event;
  for (FrameResult r; (r = source.Next(&event)) != FrameResult::kEndOfStream;) {
    EXPECT_EQ(r, FrameResult::kOk) << event.error;
    back.depth += event.kind == SourceEvent::Kind::kDepth;
  }
  back.events = source.events_read();
  back.truncated = source.truncated();
  return back;
}

// The probe held 64 slots of 67 MB each (4.8 GB RSS). Here 150
// frames of 1024 x 1024 (4 MiB each) as fast as Record() takes them: the
// slots never hold more than the 32 MiB budget, the newest frames are
// dropped and counted, and the process grows by the budget plus the
// writer's frame and its encoding (64 slots x 4 MiB = 256 MiB without the
// byte budget).
TEST(SessionRecorder, QueueStaysWithinItsByteBudgetUnderManyLargeFrames) {
  SessionRecorder::Config config;
  config.path = ScratchPath("big.lcmlog");
  config.queue_capacity = 64;
  config.queue_bytes = 32 * kMiB;
  DepthFrame frame = NoisyFrame(1024, 1024);
  const double rss_before_mb = ResidentMemoryMb();
  ASSERT_GT(rss_before_mb, 0.0);
  double rss_peak_mb = rss_before_mb;
  constexpr int kFrames = 150;
  SessionRecorder recorder(config, Session());
  for (int i = 0; i < kFrames; ++i) {
    frame.utime = 1000000 + i * 33333;
    recorder.RecordDepth(frame);
    EXPECT_LE(recorder.queue_bytes(), config.queue_bytes);
    rss_peak_mb = std::max(rss_peak_mb, ResidentMemoryMb());
  }
  recorder.Close();
  rss_peak_mb = std::max(rss_peak_mb, ResidentMemoryMb());
  EXPECT_LE(recorder.queue_bytes_peak(), config.queue_bytes);
  EXPECT_GE(recorder.queue_bytes_peak(), 4 * kMiB);
  EXPECT_GT(recorder.events_dropped(), 0);  // the budget, not the 64 slots, held them back
  EXPECT_EQ(recorder.events_written() + recorder.events_dropped(), kFrames);
  EXPECT_EQ(recorder.failure(), "");
  const double growth_mb = rss_peak_mb - rss_before_mb;
  EXPECT_LT(growth_mb, 32.0 * 1.048576 + 3 * 4.2 + 20.0)
      << "written " << recorder.events_written() << ", dropped " << recorder.events_dropped();
  std::printf("recorder: %lld written, %lld dropped, slots' peak %.1f MiB, RSS +%.1f MB\n",
              static_cast<long long>(recorder.events_written()),
              static_cast<long long>(recorder.events_dropped()), recorder.queue_bytes_peak() / double(kMiB),
              growth_mb);

  const ReadBack back = ReadAll(config.path);
  EXPECT_EQ(back.events, recorder.events_written() + 1);  // and the session description
  EXPECT_EQ(back.depth, recorder.events_written());
  EXPECT_FALSE(back.truncated);
}

// Frames of changing sizes reuse the free slots' buffers instead of
// growing every slot to the largest (the slots' sum stays in the budget).
TEST(SessionRecorder, MixedFrameSizesStayWithinTheBudget) {
  SessionRecorder::Config config;
  config.path = ScratchPath("mixed.lcmlog");
  config.queue_bytes = 8 * kMiB;
  const DepthFrame small = NoisyFrame(64, 48);
  const DepthFrame large = NoisyFrame(1024, 512);  // 2 MiB
  SessionRecorder recorder(config, Session());
  GripperState state;
  state.joint_values.assign(6, 0.1);
  for (int i = 0; i < 200; ++i) {
    DepthFrame f = i % 3 == 0 ? large : small;
    f.utime = 1000 + i;
    recorder.RecordDepth(f);
    state.utime = 1000 + i;
    recorder.RecordGripperState(state);
    EXPECT_LE(recorder.queue_bytes(), config.queue_bytes);
  }
  recorder.Close();
  EXPECT_LE(recorder.queue_bytes_peak(), config.queue_bytes);
  EXPECT_EQ(recorder.events_written() + recorder.events_dropped(), 400);
  EXPECT_EQ(ReadAll(config.path).events, recorder.events_written() + 1);
}

// A full disk (RLIMIT_FSIZE: EFBIG; a real ENOSPC in live_record_faults.sh):
// the recording stops, failure() says why, the log keeps every whole event
// written before (readable, no partial tail), later events are counted as
// dropped, and Close() does not throw: the session goes on.
TEST(SessionRecorder, AFullDiskStopsTheRecordingAndTheLogKeepsWhatWasWritten) {
  SessionRecorder::Config config;
  config.path = ScratchPath("full.lcmlog");
  config.sync_period_ms = 0;
  const DepthFrame frame = NoisyFrame(320, 240);  // ~100 KB a frame in ZLIB16
  constexpr int kFrames = 40;
  {
    testing::FileSizeLimit full(300 << 10);
    ASSERT_TRUE(full.ok());
    SessionRecorder recorder(config, Session());
    for (int i = 0; i < kFrames; ++i) {
      DepthFrame f = frame;
      f.utime = 1000 + i;
      recorder.RecordDepth(f);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));  // the writer keeps up
    }
    EXPECT_NO_THROW(recorder.Close());
    EXPECT_NE(recorder.failure().find("cannot write log '" + config.path + "': " + std::strerror(EFBIG)),
              std::string::npos)
        << recorder.failure();
    EXPECT_GE(recorder.events_written(), 1);
    EXPECT_EQ(recorder.events_written() + recorder.events_dropped(), kFrames);
    recorder.RecordDepth(frame);  // after Close: ignored
    const ReadBack back = ReadAll(config.path);
    EXPECT_EQ(back.events, recorder.events_written() + 1);
    EXPECT_EQ(back.depth, recorder.events_written());
    EXPECT_FALSE(back.truncated);
    EXPECT_LE(fs::file_size(config.path), uintmax_t{300} << 10);
  }
}

TEST(SessionRecorder, RefusesBudgetsTooSmallAndNegativeSyncPeriods) {
  SessionRecorder::Config config;
  config.path = ScratchPath("x.lcmlog");
  config.queue_bytes = 1000;
  EXPECT_THROW(SessionRecorder(config, Session()), std::invalid_argument);
  config.queue_bytes = kMiB;
  config.sync_period_ms = -1;
  EXPECT_THROW(SessionRecorder(config, Session()), std::invalid_argument);
  EXPECT_FALSE(fs::exists(config.path));
}

}  // namespace
}  // namespace graspfill::rt
