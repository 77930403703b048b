// SPDX-License-Identifier: BSD-3-Clause
// LCM log round trips: LcmLogWriter -> LcmLogSource, channel filtering,
// truncation and open errors.
#include <gtest/gtest.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <stdexcept>
#include <vector>

#include <sys/stat.h>
#include <lcm/lcm-cpp.hpp>

#include "../io/file_size_limit.hpp"

#include "graspfill/io/messages.hpp"
#include "sinks/lcm_log_writer.hpp"
#include "sources/lcm_log_source.hpp"

namespace graspfill::rt {
namespace {

namespace fs = std::filesystem;

class LcmLogTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(GRASPFILL_BINARY_DIR) / "test_tmp" / "rt_lcm_log" / info->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

DepthFrame SmallDepth(int64_t utime, float depth_m) {
  DepthFrame frame;
  frame.utime = utime;
  frame.intrinsics = {8, 6, 10.0, 10.0, 3.5, 2.5};
  frame.depth_m.assign(48, depth_m);
  frame.depth_m[5] = 0.0f;
  return frame;
}

GripperState SomeGripper(int64_t utime, double x) {
  GripperState state;
  state.utime = utime;
  state.T_C_G.translation() = Eigen::Vector3d(x, 0.0, 0.5);
  state.opening_m = 0.03;
  return state;
}

// depth(1.0 m), gripper, other channel, depth(1.5 m): 4 events. Returns
// the size of the last event in the file [bytes].
uintmax_t WriteSampleLog(const std::string& path) {
  const io::ChannelNames channels;
  LcmLogWriter writer(path);
  writer.Write(channels.depth, 100, io::EncodeDepthImage(SmallDepth(100, 1.0f)));
  writer.Write(channels.gripper_state, 110, io::EncodeGripperState(SomeGripper(110, 0.2)));
  writer.Write("SOMEONE_ELSES_CHANNEL", 115, {1, 2, 3, 4});
  const auto last = io::EncodeDepthImage(SmallDepth(133, 1.5f), io::DepthEncoding::kRaw16);
  writer.Write(channels.depth, 133, last);
  EXPECT_EQ(writer.events_written(), 4);
  // Sync word, event number, timestamp, channel and data lengths, channel.
  return 4 + 8 + 8 + 4 + 4 + channels.depth.size() + last.size();
}

LcmLogSource::Config SourceConfig(const std::string& path) {
  LcmLogSource::Config config;
  config.path = path;
  return config;
}

TEST_F(LcmLogTest, EventsComeBackInOrderAndOtherChannelsAreSkipped) {
  WriteSampleLog(Path("sample.lcmlog"));
  LcmLogSource source(SourceConfig(Path("sample.lcmlog")));
  SourceEvent event;

  ASSERT_EQ(source.Next(&event), FrameResult::kOk) << event.error;
  EXPECT_EQ(event.kind, SourceEvent::Kind::kDepth);
  EXPECT_EQ(event.depth.utime, 100);
  EXPECT_EQ(event.depth.intrinsics, SmallDepth(0, 0).intrinsics);
  EXPECT_EQ(event.depth.depth_m[0], 1.0f);
  EXPECT_EQ(event.depth.depth_m[5], 0.0f);

  ASSERT_EQ(source.Next(&event), FrameResult::kOk) << event.error;
  EXPECT_EQ(event.kind, SourceEvent::Kind::kGripperState);
  EXPECT_EQ(event.gripper.utime, 110);
  EXPECT_TRUE(event.gripper.T_C_G.translation().isApprox(Eigen::Vector3d(0.2, 0.0, 0.5)));
  EXPECT_EQ(event.gripper.opening_m, 0.03);

  ASSERT_EQ(source.Next(&event), FrameResult::kOk) << event.error;
  EXPECT_EQ(event.kind, SourceEvent::Kind::kDepth);
  EXPECT_EQ(event.depth.utime, 133);
  EXPECT_EQ(event.depth.depth_m[1], 1.5f);

  EXPECT_EQ(source.Next(&event), FrameResult::kEndOfStream);
  EXPECT_EQ(source.Next(&event), FrameResult::kEndOfStream);
  EXPECT_EQ(source.events_read(), 4);
  EXPECT_EQ(source.skipped_other_channels(), 1);
  EXPECT_FALSE(source.truncated());
  const std::vector<std::string> expected = {"GRASPFILL_DEPTH", "GRASPFILL_GRIPPER_STATE",
                                             "SOMEONE_ELSES_CHANNEL"};
  EXPECT_EQ(source.channels_seen(), expected);
}

TEST_F(LcmLogTest, RenamedChannelsAndBaseFrameStates) {
  graspfill::rt::LcmLogSource::Config config = SourceConfig(Path("b.lcmlog"));
  config.channels.depth = "CAM";
  config.channels.gripper_state = "ARM";
  config.overrides.T_C_B.translation() = Eigen::Vector3d(0.0, 0.0, 1.0);
  {
    LcmLogWriter writer(config.path);
    writer.Write("GRASPFILL_DEPTH", 1, io::EncodeDepthImage(SmallDepth(1, 1)));
    writer.Write("CAM", 2, io::EncodeDepthImage(SmallDepth(2, 2)));
    // Forge a base-frame state by flipping the encoded frame byte (after
    // the 8-byte hash and 8-byte utime).
    auto bytes = io::EncodeGripperState(SomeGripper(3, 0.1));
    bytes[16] = 1;  // FRAME_BASE
    writer.Write("ARM", 3, bytes);
  }
  LcmLogSource source(config);
  SourceEvent event;
  ASSERT_EQ(source.Next(&event), FrameResult::kOk);
  EXPECT_EQ(event.depth.utime, 2);
  ASSERT_EQ(source.Next(&event), FrameResult::kOk);
  ASSERT_EQ(event.kind, SourceEvent::Kind::kGripperState);
  // T_C_G = T_C_B * T_B_G: shifted 1 m along the camera's z.
  EXPECT_TRUE(event.gripper.T_C_G.translation().isApprox(Eigen::Vector3d(0.1, 0.0, 1.5)));
  EXPECT_EQ(source.Next(&event), FrameResult::kEndOfStream);
  EXPECT_EQ(source.skipped_other_channels(), 1);
}

TEST_F(LcmLogTest, UndecodableEventIsABadFrameAndReadingGoesOn) {
  {
    LcmLogWriter writer(Path("bad.lcmlog"));
    writer.Write("GRASPFILL_DEPTH", 1, {0xde, 0xad, 0xbe, 0xef});
    auto gripper = io::EncodeGripperState(SomeGripper(2, 0.0));
    gripper.pop_back();
    writer.Write("GRASPFILL_GRIPPER_STATE", 2, gripper);
    writer.Write("GRASPFILL_DEPTH", 3, io::EncodeDepthImage(SmallDepth(3, 1)));
  }
  LcmLogSource source(SourceConfig(Path("bad.lcmlog")));
  SourceEvent event;
  EXPECT_EQ(source.Next(&event), FrameResult::kBadFrame);
  EXPECT_EQ(event.kind, SourceEvent::Kind::kDepth);
  EXPECT_NE(event.error.find("depth_image_t"), std::string::npos) << event.error;
  EXPECT_EQ(source.Next(&event), FrameResult::kBadFrame);
  EXPECT_EQ(event.kind, SourceEvent::Kind::kGripperState);
  EXPECT_NE(event.error.find("gripper_state_t"), std::string::npos) << event.error;
  ASSERT_EQ(source.Next(&event), FrameResult::kOk);
  EXPECT_EQ(event.depth.utime, 3);
  EXPECT_EQ(source.Next(&event), FrameResult::kEndOfStream);
  EXPECT_FALSE(source.truncated());
}

TEST_F(LcmLogTest, TruncatedLogIsDetected) {
  const uintmax_t last = WriteSampleLog(Path("full.lcmlog"));
  const auto full_size = fs::file_size(Path("full.lcmlog"));
  // Cut inside the last event's data, channel name, header fields and sync
  // word (1 to 3 of its 4 bytes left), from the end of the file.
  const uintmax_t data = last - 28 - 15;
  for (uintmax_t cut : {uintmax_t{1}, uintmax_t{2}, uintmax_t{10}, data, data + 5, data + 15 + 2,
                        data + 15 + 6, last - 20, last - 3, last - 2, last - 1}) {
    SCOPED_TRACE("cut " + std::to_string(cut));
    const std::string path = Path("cut" + std::to_string(cut) + ".lcmlog");
    fs::copy_file(Path("full.lcmlog"), path);
    fs::resize_file(path, full_size - cut);
    LcmLogSource source(SourceConfig(path));
    SourceEvent event;
    int ok = 0;
    while (source.Next(&event) != FrameResult::kEndOfStream) ++ok;
    EXPECT_EQ(ok, 2);  // the cut depth image is lost, the others survive
    EXPECT_TRUE(source.truncated());
    EXPECT_EQ(source.events_read(), 3);
  }
}

TEST_F(LcmLogTest, LogCutAtAnEventBoundaryIsNotTruncated) {
  {
    LcmLogWriter writer(Path("one.lcmlog"));
    writer.Write("GRASPFILL_DEPTH", 1, io::EncodeDepthImage(SmallDepth(1, 1)));
  }
  const auto one_event = fs::file_size(Path("one.lcmlog"));
  WriteSampleLog(Path("full.lcmlog"));
  fs::resize_file(Path("full.lcmlog"), one_event);
  LcmLogSource source(SourceConfig(Path("full.lcmlog")));
  SourceEvent event;
  EXPECT_EQ(source.Next(&event), FrameResult::kOk);
  EXPECT_EQ(source.Next(&event), FrameResult::kEndOfStream);
  EXPECT_FALSE(source.truncated());
}

TEST_F(LcmLogTest, EmptyFileIsAnEmptyLog) {
  std::ofstream(Path("empty.lcmlog")).close();
  LcmLogSource source(SourceConfig(Path("empty.lcmlog")));
  SourceEvent event;
  EXPECT_EQ(source.Next(&event), FrameResult::kEndOfStream);
  EXPECT_FALSE(source.truncated());
  EXPECT_EQ(source.events_read(), 0);
}

void ExpectThrowsWith(const std::function<void()>& f, const std::string& expected) {
  try {
    f();
    ADD_FAILURE() << "no exception, expected '" << expected << "'";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
}

TEST_F(LcmLogTest, OpenErrorsNameTheFile) {
  const std::string missing = Path("missing.lcmlog");
  ExpectThrowsWith([&] { LcmLogSource source(SourceConfig(missing)); },
                   "cannot open log '" + missing + "': no such file");
  ExpectThrowsWith([&] { LcmLogSource source(SourceConfig(Path(""))); }, "is a directory");
  std::ofstream(Path("text.lcmlog")) << "hello, not a log\n";
  ExpectThrowsWith([&] { LcmLogSource source(SourceConfig(Path("text.lcmlog"))); },
                   "'" + Path("text.lcmlog") + "' is not an LCM log");
}

TEST_F(LcmLogTest, WriterRefusesToClobber) {
  WriteSampleLog(Path("log.lcmlog"));
  ExpectThrowsWith([&] { LcmLogWriter writer(Path("log.lcmlog")); },
                   "cannot create log '" + Path("log.lcmlog") + "': file exists");
  {
    LcmLogWriter writer(Path("log.lcmlog"), /*overwrite=*/true);
    writer.Write("X", 1, {});
  }
  LcmLogSource source(SourceConfig(Path("log.lcmlog")));
  SourceEvent event;
  EXPECT_EQ(source.Next(&event), FrameResult::kEndOfStream);
  EXPECT_EQ(source.events_read(), 1);
  EXPECT_EQ(source.channels_seen(), std::vector<std::string>{"X"});

  ExpectThrowsWith([&] { LcmLogWriter writer(Path("no/dir/x.lcmlog")); },
                   "cannot create log '" + Path("no/dir/x.lcmlog") + "'");
  LcmLogWriter writer(Path("w.lcmlog"));
  ExpectThrowsWith([&] { writer.Write("", 1, {}); }, "bad channel name");
}

// Atomic logs (synth's): the events go to a temporary file renamed into
// place on Close() (or destruction); a full disk (RLIMIT_FSIZE, see
// file_size_limit.hpp) or an exception unwinding past the writer leaves the
// previous log and no temporary file.
size_t FilesIn(const std::string& dir) {
  return static_cast<size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

TEST_F(LcmLogTest, LogAppearsWhenClosedAndFailuresKeepThePreviousOne) {
  const std::string path = Path("atomic.lcmlog");
  const std::string dir = fs::path(path).parent_path().string();
  {
    LcmLogWriter writer(path);
    writer.Write("X", 1, {1, 2, 3});
    writer.Flush();
    EXPECT_FALSE(fs::exists(path));  // not yet: only the temporary file
    writer.Close();
    EXPECT_TRUE(fs::exists(path));
    ExpectThrowsWith([&] { writer.Write("X", 2, {}); }, "closed");
  }
  const auto good_size = fs::file_size(path);
  const size_t files = FilesIn(dir);

  // Full disk: the write fails with the system's reason, the old log stays.
  {
    testing::FileSizeLimit full(4096);
    ASSERT_TRUE(full.ok());
    ExpectThrowsWith(
        [&] {
          LcmLogWriter writer(path, /*overwrite=*/true);
          for (int i = 0; i < 100; ++i) writer.Write("X", i, std::vector<uint8_t>(1000, 7));
          writer.Close();
        },
        "cannot write log '" + path + "': " + std::strerror(EFBIG));
  }
  EXPECT_EQ(fs::file_size(path), good_size);
  EXPECT_EQ(FilesIn(dir), files);

  // An exception from elsewhere while the log is being written.
  try {
    LcmLogWriter writer(path, /*overwrite=*/true);
    writer.Write("X", 1, std::vector<uint8_t>(100, 1));
    throw std::runtime_error("rendering failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(fs::file_size(path), good_size);
  EXPECT_EQ(FilesIn(dir), files);
  LcmLogSource source(SourceConfig(path));
  SourceEvent event;
  EXPECT_EQ(source.Next(&event), FrameResult::kEndOfStream);
  EXPECT_EQ(source.events_read(), 1);
}

TEST_F(LcmLogTest, WriterRefusesADanglingSymlinkWithoutOverwrite) {
  fs::create_symlink(Path("elsewhere.lcmlog"), Path("link.lcmlog"));
  ExpectThrowsWith([&] { LcmLogWriter writer(Path("link.lcmlog")); }, "file exists");
  EXPECT_FALSE(fs::exists(Path("elsewhere.lcmlog")));
}

// ---- Session descriptions ---------------------------------------------------------

io::SessionDescription SomeSession() {
  io::SessionDescription session;
  session.claw_name = "parallel";
  session.claw_text = "{}";
  return session;
}

// A gripper state in the base frame B, as a robot publishes it: the
// encoder writes camera-frame poses, so flip the frame byte (after the
// 8-byte hash and the 8-byte utime).
std::vector<uint8_t> BaseFrameState(int64_t utime, double x) {
  auto bytes = io::EncodeGripperState(SomeGripper(utime, x));
  bytes[16] = 1;  // FRAME_BASE
  return bytes;
}

// session(T_C_B = 1 m along z, intrinsics override), base-frame state,
// depth; then a second session (identity, no override), state, depth.
void WriteSessionLog(const std::string& path) {
  const io::ChannelNames ch;
  LcmLogWriter writer(path);
  writer.Write(ch.gripper_state, 1, BaseFrameState(1, 0.1));  // before any session
  io::SessionDescription first = SomeSession();
  first.utime = 2;
  first.T_C_B.translation() = Eigen::Vector3d(0.0, 0.0, 1.0);
  first.intrinsics = CameraIntrinsics{8, 6, 20.0, 21.0, 4.0, 3.0};
  writer.Write(ch.session, 2, io::EncodeSessionDescription(first));
  writer.Write(ch.gripper_state, 3, BaseFrameState(3, 0.1));
  writer.Write(ch.depth, 4, io::EncodeDepthImage(SmallDepth(4, 1.0f)));
  io::SessionDescription second = SomeSession();
  second.utime = 5;
  second.claw_name = "three-finger";
  writer.Write(ch.session, 5, io::EncodeSessionDescription(second));
  writer.Write(ch.gripper_state, 6, BaseFrameState(6, 0.1));
  writer.Write(ch.depth, 7, io::EncodeDepthImage(SmallDepth(7, 1.0f)));
}

TEST_F(LcmLogTest, SessionDescriptionsAreEventsWhenAskedFor) {
  WriteSessionLog(Path("s.lcmlog"));
  LcmLogSource::Config config = SourceConfig(Path("s.lcmlog"));
  config.session_events = true;
  LcmLogSource source(config);
  std::vector<SourceEvent::Kind> kinds;
  std::vector<std::string> claws;
  SourceEvent event;
  for (FrameResult r; (r = source.Next(&event)) != FrameResult::kEndOfStream;) {
    ASSERT_EQ(r, FrameResult::kOk) << event.error;
    kinds.push_back(event.kind);
    if (event.kind == SourceEvent::Kind::kSession) claws.push_back(event.session.claw_name);
  }
  using K = SourceEvent::Kind;
  const std::vector<K> expected = {K::kGripperState, K::kSession,      K::kGripperState, K::kDepth,
                                   K::kSession,      K::kGripperState, K::kDepth};
  EXPECT_EQ(kinds, expected);
  EXPECT_EQ(claws, (std::vector<std::string>{"parallel", "three-finger"}));
  EXPECT_EQ(source.sessions_read(), 2);
  EXPECT_EQ(source.skipped_other_channels(), 0);
}

TEST_F(LcmLogTest, SessionSetsHandEyeAndIntrinsicsForWhatFollows) {
  WriteSessionLog(Path("s.lcmlog"));
  LcmLogSource source(SourceConfig(Path("s.lcmlog")));  // sessions not returned
  SourceEvent event;
  // Before the session: identity T_C_B.
  ASSERT_EQ(source.Next(&event), FrameResult::kOk) << event.error;
  ASSERT_EQ(event.kind, SourceEvent::Kind::kGripperState);
  EXPECT_TRUE(event.gripper.T_C_G.translation().isApprox(Eigen::Vector3d(0.1, 0.0, 0.5)));
  // After it: T_C_G = T_C_B * T_B_G, 1 m further along the camera's z, and
  // the depth image with the session's intrinsics.
  ASSERT_EQ(source.Next(&event), FrameResult::kOk) << event.error;
  ASSERT_EQ(event.kind, SourceEvent::Kind::kGripperState);
  EXPECT_TRUE(event.gripper.T_C_G.translation().isApprox(Eigen::Vector3d(0.1, 0.0, 1.5)));
  ASSERT_EQ(source.Next(&event), FrameResult::kOk) << event.error;
  ASSERT_EQ(event.kind, SourceEvent::Kind::kDepth);
  EXPECT_EQ(event.depth.intrinsics, (CameraIntrinsics{8, 6, 20.0, 21.0, 4.0, 3.0}));
  EXPECT_EQ(event.depth.depth_m[0], 1.0f);
  // The second session resets both.
  ASSERT_EQ(source.Next(&event), FrameResult::kOk) << event.error;
  EXPECT_TRUE(event.gripper.T_C_G.translation().isApprox(Eigen::Vector3d(0.1, 0.0, 0.5)));
  ASSERT_EQ(source.Next(&event), FrameResult::kOk) << event.error;
  EXPECT_EQ(event.depth.intrinsics, SmallDepth(0, 0).intrinsics);
  EXPECT_EQ(source.Next(&event), FrameResult::kEndOfStream);
  EXPECT_EQ(source.sessions_read(), 2);
}

TEST_F(LcmLogTest, ConfigCanIgnoreTheSessionsHandEyeAndIntrinsics) {
  WriteSessionLog(Path("s.lcmlog"));
  LcmLogSource::Config config = SourceConfig(Path("s.lcmlog"));
  config.overrides.T_C_B.translation() = Eigen::Vector3d(0.0, 0.2, 0.0);  // e.g. from the command line
  config.overrides.T_C_B_from_session = false;
  config.overrides.intrinsics_from_session = false;
  LcmLogSource source(config);
  SourceEvent event;
  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(source.Next(&event), FrameResult::kOk) << event.error;
    if (event.kind == SourceEvent::Kind::kGripperState) {
      EXPECT_TRUE(event.gripper.T_C_G.translation().isApprox(Eigen::Vector3d(0.1, 0.2, 0.5)));
    } else {
      EXPECT_EQ(event.depth.intrinsics, SmallDepth(0, 0).intrinsics);
    }
  }
}

// A rig config's intrinsics override and clock offset (cmd_replay's
// --config): the override holds over the sessions', the offset moves every
// gripper state's stamp.
TEST_F(LcmLogTest, ConfigIntrinsicsAndClockOffsetHoldOverTheSessions) {
  WriteSessionLog(Path("s.lcmlog"));
  LcmLogSource::Config config = SourceConfig(Path("s.lcmlog"));
  const CameraIntrinsics K{8, 6, 30.0, 31.0, 3.5, 2.5};
  config.overrides.intrinsics = K;
  config.overrides.intrinsics_from_session = false;
  config.overrides.gripper_clock_offset_us = 40000;
  LcmLogSource source(config);
  std::vector<int64_t> state_utimes, depth_utimes;
  SourceEvent event;
  for (FrameResult r; (r = source.Next(&event)) != FrameResult::kEndOfStream;) {
    ASSERT_EQ(r, FrameResult::kOk) << event.error;
    if (event.kind == SourceEvent::Kind::kGripperState) state_utimes.push_back(event.gripper.utime);
    if (event.kind == SourceEvent::Kind::kDepth) {
      depth_utimes.push_back(event.depth.utime);
      EXPECT_EQ(event.depth.intrinsics, K);
    }
  }
  EXPECT_EQ(depth_utimes, (std::vector<int64_t>{4, 7}));  // the camera's clock: unmoved
  EXPECT_EQ(state_utimes, (std::vector<int64_t>{40001, 40003, 40006}));
}

TEST_F(LcmLogTest, DepthOfAnotherSizeThanTheOverrideAndBadSessionsAreBadFrames) {
  const io::ChannelNames ch;
  {
    LcmLogWriter writer(Path("s.lcmlog"));
    auto bad = io::EncodeSessionDescription(SomeSession());
    bad.pop_back();
    writer.Write(ch.session, 1, bad);
    io::SessionDescription session = SomeSession();
    session.intrinsics = CameraIntrinsics{640, 480, 500.0, 500.0, 320.0, 240.0};
    writer.Write(ch.session, 2, io::EncodeSessionDescription(session));
    writer.Write(ch.depth, 3, io::EncodeDepthImage(SmallDepth(3, 1.0f)));  // 8 x 6
  }
  LcmLogSource source(SourceConfig(Path("s.lcmlog")));
  SourceEvent event;
  EXPECT_EQ(source.Next(&event), FrameResult::kBadFrame);
  EXPECT_EQ(event.kind, SourceEvent::Kind::kSession);
  EXPECT_NE(event.error.find("session_description_t"), std::string::npos) << event.error;
  EXPECT_EQ(source.Next(&event), FrameResult::kBadFrame);
  EXPECT_EQ(event.kind, SourceEvent::Kind::kDepth);
  EXPECT_NE(event.error.find("depth image of 8x6 pixels, but the intrinsics override (the "
                             "session description's or the rig config's) is for 640x480 images"),
            std::string::npos)
      << event.error;
  EXPECT_EQ(source.Next(&event), FrameResult::kEndOfStream);
  EXPECT_EQ(source.sessions_read(), 1);
}

// Issue 12: a 48-byte log whose event declares datalen 0x7fffffff (and logs
// declaring lengths near 2^31) segfaulted liblcm's reader; now the source
// ends there, truncated, naming the offset and the field.
TEST_F(LcmLogTest, EventDeclaringHugeDataIsTruncationNotACrash) {
  for (uint32_t datalen : {0x7fffffffu, 0x7ffffff0u, 0x10000000u, 0x80000000u}) {
    SCOPED_TRACE(datalen);
    std::vector<char> bytes = {char(0xED), char(0xA1), char(0xDA), char(0x01)};
    bytes.resize(4 + 16, 0);
    const uint32_t channel_len = 15;
    for (uint32_t v : {channel_len, datalen}) {
      for (int i = 3; i >= 0; --i) bytes.push_back(static_cast<char>(v >> (8 * i)));
    }
    const std::string channel = "GRASPFILL_DEPTH";
    bytes.insert(bytes.end(), channel.begin(), channel.end());
    bytes.resize(48, 'x');
    const std::string path = Path("huge" + std::to_string(datalen) + ".lcmlog");
    std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    LcmLogSource source(SourceConfig(path));
    SourceEvent event;
    EXPECT_EQ(source.Next(&event), FrameResult::kEndOfStream);
    EXPECT_TRUE(source.truncated());
    EXPECT_EQ(source.events_read(), 0);
    EXPECT_NE(source.stop_reason().find("log '" + path + "', event at byte 0: "), std::string::npos)
        << source.stop_reason();
  }
}

TEST_F(LcmLogTest, DepthOverTheConfiguredPixelLimitIsABadFrame) {
  WriteSampleLog(Path("sample.lcmlog"));  // 8 x 6 images
  LcmLogSource::Config config = SourceConfig(Path("sample.lcmlog"));
  config.max_depth_pixels = 47;
  LcmLogSource source(config);
  SourceEvent event;
  EXPECT_EQ(source.Next(&event), FrameResult::kBadFrame);
  EXPECT_NE(event.error.find("bad image size 8x6: over the limit of 47 pixels"), std::string::npos)
      << event.error;
  config.max_depth_pixels = 48;
  LcmLogSource at_limit(config);
  EXPECT_EQ(at_limit.Next(&event), FrameResult::kOk) << event.error;
}

// ---- In-place logs (live recordings, issue 36) ----------------------------------

LcmLogWriter::Options InPlace(bool overwrite = false) {
  return LcmLogWriter::Options{overwrite, LcmLogWriter::Mode::kInPlace};
}

// Reads `path` to its end: whole events read, and whether it ended in a
// partial event.
struct ReadBack {
  int64_t events{0};
  bool truncated{false};
  bool partial_last_event{false};
  int64_t unread_bytes{0};
};
ReadBack ReadAll(const std::string& path) {
  LcmLogSource source(SourceConfig(path));
  SourceEvent event;
  while (source.Next(&event) != FrameResult::kEndOfStream) {
  }
  return {source.events_read(), source.truncated(), source.partial_last_event(), source.unread_bytes()};
}

// A killed recorder leaves the log as it was after its last write: at its
// name (no temporary file), every event written whole and readable.
TEST_F(LcmLogTest, InPlaceLogIsAtItsNameAndReadableWhileItIsWritten) {
  const std::string path = Path("live.lcmlog");
  LcmLogWriter writer(path, InPlace());
  EXPECT_TRUE(fs::exists(path));
  EXPECT_EQ(FilesIn(dir_.string()), 1u);
  const io::ChannelNames channels;
  for (int i = 0; i < 5; ++i) {
    writer.Write(channels.depth, 100 + i, io::EncodeDepthImage(SmallDepth(100 + i, 1.0f)));
  }
  // No Close(): as a SIGKILL leaves it.
  EXPECT_EQ(static_cast<int64_t>(fs::file_size(path)), writer.bytes_written());
  const ReadBack back = ReadAll(path);
  EXPECT_EQ(back.events, 5);
  EXPECT_FALSE(back.truncated);
  EXPECT_EQ(FilesIn(dir_.string()), 1u);
}

// What a kill in the middle of a write(2), or a power cut, can leave: a
// partial last event. The reader ends there with a note; the events before
// it are all read. A corrupt event in the middle still stops as before.
TEST_F(LcmLogTest, PartialLastEventEndsTheLogAndTheEventsBeforeItAreRead) {
  const uintmax_t last = WriteSampleLog(Path("full.lcmlog"));
  const auto full_size = fs::file_size(Path("full.lcmlog"));
  for (uintmax_t keep : {uintmax_t{1}, uintmax_t{27}, uintmax_t{40}, last - 1}) {
    SCOPED_TRACE(keep);
    const std::string path = Path("cut" + std::to_string(keep) + ".lcmlog");
    fs::copy_file(Path("full.lcmlog"), path);
    fs::resize_file(path, full_size - last + keep);
    const ReadBack back = ReadAll(path);
    EXPECT_EQ(back.events, 3);  // the 3 whole events before the cut one
    EXPECT_TRUE(back.truncated);
    EXPECT_TRUE(back.partial_last_event);
    EXPECT_EQ(back.unread_bytes, static_cast<int64_t>(keep));
  }
  // A sync word broken in the second event: corrupt, not a partial tail.
  const std::string corrupt = Path("corrupt.lcmlog");
  fs::copy_file(Path("full.lcmlog"), corrupt);
  {
    io::LcmLogReader reader(Path("full.lcmlog"));
    io::LogEvent e;
    ASSERT_EQ(reader.Next(&e), io::LogReadResult::kEvent);
    std::fstream f(corrupt, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(reader.offset());
    f.put('\0');
  }
  const ReadBack back = ReadAll(corrupt);
  EXPECT_EQ(back.events, 1);
  EXPECT_TRUE(back.truncated);
  EXPECT_FALSE(back.partial_last_event);
}

// The bytes are lcm-logger's: liblcm's own writer makes the same file.
TEST_F(LcmLogTest, InPlaceLogIsByteForByteWhatLiblcmWrites) {
  struct Event {
    std::string channel;
    int64_t utime;
    std::vector<uint8_t> data;
  };
  const std::vector<Event> events = {
      {"GRASPFILL_SESSION", 90, {}},
      {"GRASPFILL_DEPTH", 100, io::EncodeDepthImage(SmallDepth(100, 1.0f))},
      {"GRASPFILL_GRIPPER_STATE", -5, io::EncodeGripperState(SomeGripper(110, 0.2))},
      {std::string(255, 'c'), int64_t{1} << 62, std::vector<uint8_t>(70000, 0xab)}};
  {
    LcmLogWriter ours(Path("ours.lcmlog"), InPlace());
    for (const Event& e : events) ours.Write(e.channel, e.utime, e.data);
    ours.Close();
  }
  {
    lcm::LogFile theirs(Path("lcm.lcmlog"), "w");
    ASSERT_TRUE(theirs.good());
    for (const Event& e : events) {
      lcm::LogEvent event;
      event.eventnum = 0;
      event.timestamp = e.utime;
      event.channel = e.channel;
      event.datalen = static_cast<int32_t>(e.data.size());
      event.data = const_cast<uint8_t*>(e.data.data());
      ASSERT_EQ(theirs.writeEvent(&event), 0);
    }
  }
  std::ifstream a(Path("ours.lcmlog"), std::ios::binary), b(Path("lcm.lcmlog"), std::ios::binary);
  const std::vector<char> ours((std::istreambuf_iterator<char>(a)), std::istreambuf_iterator<char>());
  const std::vector<char> theirs((std::istreambuf_iterator<char>(b)), std::istreambuf_iterator<char>());
  EXPECT_GT(ours.size(), 70000u);
  EXPECT_TRUE(ours == theirs);
}

// O_EXCL without overwrite: an existing file (or link) is never touched.
// With overwrite, only a regular file is replaced: a FIFO, a device or a
// folder is refused (a FIFO would block the open or swallow the log).
TEST_F(LcmLogTest, InPlaceWriterNeverClobbersAndWritesOnlyRegularFiles) {
  const std::string old_log = Path("old.lcmlog");
  WriteSampleLog(old_log);
  const auto old_size = fs::file_size(old_log);
  ExpectThrowsWith([&] { LcmLogWriter writer(old_log, InPlace()); },
                   "cannot create log '" + old_log + "': file exists");
  EXPECT_EQ(fs::file_size(old_log), old_size);
  fs::create_symlink(Path("elsewhere.lcmlog"), Path("link.lcmlog"));
  ExpectThrowsWith([&] { LcmLogWriter writer(Path("link.lcmlog"), InPlace()); }, "file exists");
  EXPECT_FALSE(fs::exists(Path("elsewhere.lcmlog")));

  ASSERT_EQ(::mkfifo(Path("fifo").c_str(), 0600), 0);
  for (bool overwrite : {false, true}) {
    SCOPED_TRACE(overwrite);
    ExpectThrowsWith([&] { LcmLogWriter writer(Path("fifo"), InPlace(overwrite)); },
                     "cannot create log '" + Path("fifo") + "': not a regular file");
    ExpectThrowsWith([&] { LcmLogWriter writer(dir_.string(), InPlace(overwrite)); }, "is a directory");
    ExpectThrowsWith([&] { LcmLogWriter writer("/dev/null", InPlace(overwrite)); },
                     "cannot create log '/dev/null': not a regular file");
  }
  EXPECT_TRUE(fs::is_fifo(Path("fifo")));

  {
    LcmLogWriter writer(old_log, InPlace(/*overwrite=*/true));
    writer.Write("X", 1, {1, 2, 3});
  }
  EXPECT_EQ(ReadAll(old_log).events, 1);
}

// A full disk (RLIMIT_FSIZE here; ENOSPC in live_record_faults.sh): the
// write fails with the system's reason, the log is cut back to its last
// whole event and closed, and keeps every event written before.
TEST_F(LcmLogTest, InPlaceLogKeepsItsWholeEventsWhenTheDiskIsFull) {
  const std::string path = Path("full.lcmlog");
  int64_t written = 0;
  int64_t bytes = 0;
  {
    testing::FileSizeLimit full(10000);
    ASSERT_TRUE(full.ok());
    LcmLogWriter writer(path, InPlace());
    ExpectThrowsWith(
        [&] {
          for (int i = 0; i < 100; ++i) {
            writer.Write("X", i, std::vector<uint8_t>(1000, 7));
            ++written;
          }
        },
        "cannot write log '" + path + "': " + std::strerror(EFBIG));
    bytes = writer.bytes_written();
    ExpectThrowsWith([&] { writer.Write("X", 1, {}); }, "an earlier write failed");
  }
  EXPECT_EQ(written, 9);  // 9 x 1029 bytes fit in 10000
  EXPECT_EQ(static_cast<int64_t>(fs::file_size(path)), bytes);
  const ReadBack back = ReadAll(path);
  EXPECT_EQ(back.events, written);
  EXPECT_FALSE(back.truncated);
}

}  // namespace
}  // namespace graspfill::rt
