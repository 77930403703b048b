// Replay of the bundled recordings (regression, determinism) and of bad logs
// (clear error, non-zero exit, never a crash).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "cli_runner.hpp"
#include "graspfill/eval/metrics.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/io/ply.hpp"
#include "sinks/lcm_log_writer.hpp"

namespace graspfill {
namespace {

using testing::RunCli;
using testing::ScratchDir;

const std::string kReplayDir = std::string(GRASPFILL_SOURCE_DIR) + "/replay";

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(ReplayE2E, BundledRecordingMatchesItsRecordedOutput) {
  const std::string dir = ScratchDir("regression");
  const auto r = RunCli("replay " + kReplayDir + "/default/recording.lcmlog -o " + dir +
                        "/cloud.ply --json --lcm-url memq://");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const ObjectCloud now = io::ReadCloudPly(dir + "/cloud.ply");
  const ObjectCloud expected = io::ReadCloudPly(kReplayDir + "/default/expected_cloud.ply");
  // Same build: identical. Another compiler/Open3D build may round a voxel
  // crossing differently, so compare geometry with a 0.1 mm tolerance.
  ASSERT_NEAR(static_cast<double>(now.size()), static_cast<double>(expected.size()),
              0.01 * expected.size());
  const eval::CloudMetrics m = eval::Compare(now.points_G, expected.points_G);
  EXPECT_LT(m.p95_pred_to_gt_mm, 0.1);
  EXPECT_LT(m.p95_gt_to_pred_mm, 0.1);
}

TEST(ReplayE2E, SameLogTwiceGivesIdenticalBytes) {
  const std::string dir = ScratchDir("determinism");
  const std::string log = kReplayDir + "/default/recording.lcmlog";
  ASSERT_EQ(RunCli("replay " + log + " -o " + dir + "/a.ply --no-publish").exit_code, 0);
  ASSERT_EQ(RunCli("replay " + log + " -o " + dir + "/b.ply --no-publish").exit_code, 0);
  const std::string a = ReadBytes(dir + "/a.ply"), b = ReadBytes(dir + "/b.ply");
  ASSERT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == b);
}

TEST(ReplayE2E, RefusesToOverwriteWithoutForce) {
  const std::string dir = ScratchDir("overwrite");
  std::ofstream(dir + "/cloud.ply") << "precious";
  const auto r = RunCli("replay " + kReplayDir + "/default/recording.lcmlog -o " + dir +
                        "/cloud.ply --no-publish");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("--force"), std::string::npos) << r.output;
  EXPECT_EQ(ReadBytes(dir + "/cloud.ply"), "precious");
}

TEST(ReplayE2E, MissingLogIsAClearError) {
  const std::string dir = ScratchDir("missing");
  const auto r = RunCli("replay " + dir + "/nope.lcmlog -o " + dir + "/c.ply --no-publish");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("nope.lcmlog"), std::string::npos) << r.output;
}

TEST(ReplayE2E, TruncatedLogIsAClearError) {
  const std::string dir = ScratchDir("truncated");
  const std::string bytes = ReadBytes(kReplayDir + "/default/recording.lcmlog");
  std::ofstream(dir + "/cut.lcmlog", std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  const auto r = RunCli("replay " + dir + "/cut.lcmlog -o " + dir + "/c.ply --no-publish");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("truncated"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/c.ply"));
}

TEST(ReplayE2E, UnknownDepthChannelNamesTheChannelsSeen) {
  const std::string dir = ScratchDir("channel");
  const auto r = RunCli("replay " + kReplayDir + "/default/recording.lcmlog -o " + dir +
                        "/c.ply --no-publish --depth-channel NO_SUCH_CHANNEL");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("NO_SUCH_CHANNEL"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("GRASPFILL_DEPTH"), std::string::npos) << r.output;
}

// A small hand-made log: 10 frames of a flat wall with states every 10 ms.
class BadLogs : public ::testing::Test {
 protected:
  static DepthFrame Frame(int64_t utime, int width = 640, int height = 480) {
    DepthFrame f;
    f.utime = utime;
    f.intrinsics.width = width;
    f.intrinsics.height = height;
    f.depth_m.assign(static_cast<size_t>(width) * height, 0.5f);
    return f;
  }
  static GripperState State(int64_t utime) {
    GripperState s;
    s.utime = utime;
    s.T_C_G.translation() = Eigen::Vector3d(0, 0, 0.5);
    s.opening_m = 0.03;
    return s;
  }
  std::string Write(const std::string& name, bool wrong_size, bool nan_pose, bool sparse_states) {
    const std::string dir = ScratchDir("bad_" + name);
    rt::LcmLogWriter log(dir + "/log.lcmlog");
    const io::ChannelNames ch;
    for (int i = 0; i < 10; ++i) {
      const int64_t t = 100000 + i * 33333;
      for (int64_t s = t - 30000; s < t; s += sparse_states ? 200000 : 10000) {
        GripperState state = State(s);
        if (nan_pose && i == 5) state.T_C_G.translation().x() = std::nan("");
        log.Write(ch.gripper_state, s, io::EncodeGripperState(state));
      }
      log.Write(ch.depth, t, io::EncodeDepthImage(wrong_size && i == 3 ? Frame(t, 320, 240) : Frame(t)));
    }
    return dir;
  }
};

TEST_F(BadLogs, WrongSizedFrameFailsUnlessSkipped) {
  const std::string dir = Write("size", true, false, false);
  auto r = RunCli("replay " + dir + "/log.lcmlog -o " + dir + "/c.ply --no-publish");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("size"), std::string::npos) << r.output;
  r = RunCli("replay " + dir + "/log.lcmlog -o " + dir + "/c.ply --no-publish --skip-bad-frames --json");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("\"frames_bad\": 1"), std::string::npos) << r.output;
}

TEST_F(BadLogs, NanPoseFailsUnlessSkipped) {
  const std::string dir = Write("nan", false, true, false);
  auto r = RunCli("replay " + dir + "/log.lcmlog -o " + dir + "/c.ply --no-publish");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("not finite"), std::string::npos) << r.output;
  r = RunCli("replay " + dir + "/log.lcmlog -o " + dir + "/c.ply --no-publish --skip-bad-frames");
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

TEST_F(BadLogs, FramesWithoutNearbyStatesAreSkippedAndCounted) {
  const std::string dir = Write("sparse", false, false, true);
  const auto r = RunCli("replay " + dir + "/log.lcmlog -o " + dir + "/c.ply --no-publish --json");
  // One state per frame, 33 ms apart, before the frame: the next state
  // brackets the frame within the 50 ms gap for all but the last frame.
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("\"frames_skipped_no_pose\": 1"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace graspfill
