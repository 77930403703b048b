// SPDX-License-Identifier: BSD-3-Clause
// Replay of the bundled recordings (regression of the fusion, determinism
// of the repaired output, the repaired cloud's layout) and of bad logs
// (clear error, non-zero exit, never a crash).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "cloud_parts.hpp"
#include "eval/metrics.hpp"
#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/io/ply.hpp"
#include "sinks/lcm_log_writer.hpp"

namespace graspfill {
namespace {

using testing::ObservedPoints;
using testing::RunCli;
using testing::ScratchDir;

const std::string kReplayDir = std::string(GRASPFILL_SOURCE_DIR) + "/replay";

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(ReplayE2E, BundledRecordingMatchesItsRecordedOutput) {
  const std::string dir = ScratchDir("regression");
  // --no-refine: the expected cloud was recorded at the logged poses
  // (exact in this recording; e2e_refine_test covers the refined path).
  const auto r = RunCli("replay " + kReplayDir + "/default/recording.lcmlog -o " + dir +
                        "/cloud.ply --json --lcm-url memq:// --no-refine");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The expected cloud holds the fused points only (written with
  // --no-repair): this pins the fusion, whatever the repair adds.
  const std::vector<Eigen::Vector3f> now = ObservedPoints(io::ReadCloudPly(dir + "/cloud.ply"));
  const ObjectCloud expected = io::ReadCloudPly(kReplayDir + "/default/expected_cloud.ply");
  // Same build: identical. Another compiler/Open3D build may round a voxel
  // crossing differently, so compare geometry with a 0.1 mm tolerance.
  ASSERT_NEAR(static_cast<double>(now.size()), static_cast<double>(expected.size()), 0.01 * expected.size());
  const eval::CloudMetrics m = eval::Compare(now, expected.points_G);
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
  // The bytes compared include the repair's points, not only the fusion's.
  const ObjectCloud cloud = io::ReadCloudPly(dir + "/a.ply");
  EXPECT_LT(ObservedPoints(cloud).size(), cloud.size());
}

// The JSON report from the CLI's output (stderr is mixed in: take the
// outermost braces); discarded (not an object) if it does not parse.
nlohmann::json ParseReport(const std::string& output) {
  const size_t first = output.find('{'), last = output.rfind('}');
  if (first == std::string::npos || last == std::string::npos || last < first) return {};
  return nlohmann::json::parse(output.substr(first, last - first + 1), nullptr, false);
}

TEST(ReplayE2E, RepairAppendsToTheFusedCloudUnchanged) {
  const std::string dir = ScratchDir("repair_layout");
  const std::string log = kReplayDir + "/default/recording.lcmlog";
  const auto repaired_run = RunCli("replay " + log + " -o " + dir + "/repaired.ply --no-publish --json");
  ASSERT_EQ(repaired_run.exit_code, 0) << repaired_run.output;
  const auto fused_run =
      RunCli("replay " + log + " -o " + dir + "/fused.ply --no-publish --json --no-repair");
  ASSERT_EQ(fused_run.exit_code, 0) << fused_run.output;
  const ObjectCloud repaired = io::ReadCloudPly(dir + "/repaired.ply");
  const ObjectCloud fused = io::ReadCloudPly(dir + "/fused.ply");

  // The fused points first, point for point (normals included), observed.
  ASSERT_GT(fused.size(), 1000u);
  ASSERT_GT(repaired.size(), fused.size()) << "the repair added nothing";
  ASSERT_EQ(fused.normals_G.size(), fused.size());
  ASSERT_EQ(repaired.normals_G.size(), repaired.size()) << "normals dropped";
  for (size_t i = 0; i < fused.size(); ++i) {
    ASSERT_EQ(repaired.points_G[i], fused.points_G[i]) << "point " << i;
    ASSERT_EQ(repaired.normals_G[i], fused.normals_G[i]) << "point " << i;
    ASSERT_EQ(repaired.provenance[i], Provenance::kObserved) << "point " << i;
    ASSERT_EQ(fused.provenance[i], Provenance::kObserved) << "point " << i;
  }
  // Then only added points, each with a unit normal.
  for (size_t i = fused.size(); i < repaired.size(); ++i) {
    ASSERT_TRUE(repaired.provenance[i] == Provenance::kSurface ||
                repaired.provenance[i] == Provenance::kSymmetry)
        << "point " << i << " provenance " << static_cast<int>(repaired.provenance[i]);
    ASSERT_NEAR(repaired.normals_G[i].norm(), 1.0f, 1e-3f) << "point " << i;
  }

  // The report counts what was added; --no-repair reports no repair.
  nlohmann::json report = ParseReport(repaired_run.output);
  ASSERT_TRUE(report.is_object()) << repaired_run.output;
  EXPECT_EQ(report.value("points", size_t{0}), repaired.size());
  ASSERT_TRUE(report["repair"].is_object()) << repaired_run.output;
  EXPECT_EQ(report["repair"].value("status", ""), "repaired");
  EXPECT_EQ(report["repair"].value("points_added", size_t{0}), repaired.size() - fused.size());
  EXPECT_FALSE(report["repair"]["holes"].empty()) << repaired_run.output;
  nlohmann::json fused_report = ParseReport(fused_run.output);
  ASSERT_TRUE(fused_report.is_object()) << fused_run.output;
  EXPECT_TRUE(fused_report["repair"].is_null()) << fused_run.output;
  EXPECT_EQ(fused_report.value("points", size_t{0}), fused.size());
}

TEST(ReplayE2E, RefusesToOverwriteWithoutForce) {
  const std::string dir = ScratchDir("overwrite");
  std::ofstream(dir + "/cloud.ply") << "precious";
  const auto r =
      RunCli("replay " + kReplayDir + "/default/recording.lcmlog -o " + dir + "/cloud.ply --no-publish");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("--force"), std::string::npos) << r.output;
  EXPECT_EQ(ReadBytes(dir + "/cloud.ply"), "precious");
}

// Data safety: the output is checked before the log is read, never
// written through a symlink without --force, and a failed write (a full
// disk: the shell's `ulimit -f`, with SIGXFSZ ignored, works for root too)
// keeps the previous file and says why.
bool HasTemporaryFile(const std::string& dir) {
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().filename().string().find(".tmp-") != std::string::npos) return true;
  }
  return false;
}

TEST(ReplayE2E, UnwritableOutputIsFoundBeforeTheLogIsRead) {
  const std::string dir = ScratchDir("unwritable");
  // The log does not exist: the output's error comes first.
  for (const std::string& out : {dir + "/no/such/folder/c.ply", std::string("/proc/c.ply")}) {
    SCOPED_TRACE(out);
    const auto r = RunCli("replay " + dir + "/nope.lcmlog -o " + out + " --no-publish");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("'" + out + "' cannot be written"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("nope.lcmlog"), std::string::npos) << r.output;
  }
}

TEST(ReplayE2E, DanglingSymlinkAsOutputIsRefusedWithoutForce) {
  const std::string dir = ScratchDir("symlink");
  std::filesystem::create_symlink(dir + "/target.ply", dir + "/link.ply");
  const auto r = RunCli("replay " + kReplayDir + "/default/recording.lcmlog -o " + dir +
                        "/link.ply --no-repair --no-publish");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("is a symbolic link"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/target.ply"));
}

TEST(ReplayE2E, FullDiskKeepsThePreviousCloud) {
  const std::string dir = ScratchDir("full_disk");
  std::ofstream(dir + "/cloud.ply") << "the previous good cloud";
  const auto r = RunCli("replay " + kReplayDir + "/default/recording.lcmlog -o " + dir +
                            "/cloud.ply --force --no-repair --no-publish",
                        "trap '' XFSZ; ulimit -f 16; ");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("'" + dir + "/cloud.ply': File too large"), std::string::npos) << r.output;
  EXPECT_EQ(ReadBytes(dir + "/cloud.ply"), "the previous good cloud");
  EXPECT_FALSE(HasTemporaryFile(dir));
}

TEST(DemoE2E, OutputFolderIsNotOverwrittenWithoutForce) {
  const std::string dir = ScratchDir("demo");
  std::ofstream(dir + "/cloud.ply") << "precious";
  const auto r = RunCli("demo -o " + dir + " --no-publish");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("--force"), std::string::npos) << r.output;
  EXPECT_EQ(ReadBytes(dir + "/cloud.ply"), "precious");
  const auto forced = RunCli("demo -o " + dir + " --force --no-publish");
  EXPECT_EQ(forced.exit_code, 0) << forced.output;
  EXPECT_NE(ReadBytes(dir + "/cloud.ply"), "precious");
  EXPECT_FALSE(HasTemporaryFile(dir));
}

TEST(ReplayE2E, MissingLogIsAClearError) {
  const std::string dir = ScratchDir("missing");
  const auto r = RunCli("replay " + dir + "/nope.lcmlog -o " + dir + "/c.ply --no-publish");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("nope.lcmlog"), std::string::npos) << r.output;
}

// A recording cut short (a crash, a kill, a power cut or a full disk while
// it was written; issue 36): its partial last event is skipped with a note
// and the whole events before it replay. Bytes that are not an event
// before the end are still an error.
TEST(ReplayE2E, CutLogReplaysItsWholeEventsAndACorruptOneIsAnError) {
  const std::string dir = ScratchDir("truncated");
  const std::string bytes = ReadBytes(kReplayDir + "/default/recording.lcmlog");
  std::ofstream(dir + "/cut.lcmlog", std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  auto r = RunCli("replay " + dir + "/cut.lcmlog -o " + dir + "/c.ply --no-publish");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("note: log '" + dir + "/cut.lcmlog' ends in a partial event"), std::string::npos)
      << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir + "/c.ply"));

  // The sync word of the 20th event zeroed: corrupt, as before.
  size_t offset = 0;
  {
    io::LcmLogReader reader(kReplayDir + "/default/recording.lcmlog");
    io::LogEvent event;
    for (int i = 0; i < 20; ++i) ASSERT_EQ(reader.Next(&event), io::LogReadResult::kEvent);
    offset = static_cast<size_t>(reader.offset());
  }
  std::string corrupt = bytes;
  corrupt.replace(offset, 4, 4, '\0');
  std::ofstream(dir + "/corrupt.lcmlog", std::ios::binary)
      .write(corrupt.data(), static_cast<std::streamsize>(corrupt.size()));
  r = RunCli("replay " + dir + "/corrupt.lcmlog -o " + dir + "/d.ply --no-publish");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("is truncated after 20 events"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no sync word"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/d.ply"));
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
  // --no-refine: these frames hold no claw, so pose refinement would skip them all.
  r = RunCli("replay " + dir + "/log.lcmlog -o " + dir +
             "/c.ply --no-publish --skip-bad-frames --json --no-refine");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("\"frames_bad\": 1"), std::string::npos) << r.output;
}

TEST_F(BadLogs, NanPoseFailsUnlessSkipped) {
  const std::string dir = Write("nan", false, true, false);
  auto r = RunCli("replay " + dir + "/log.lcmlog -o " + dir + "/c.ply --no-publish");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("not finite"), std::string::npos) << r.output;
  // --no-refine: these frames hold no claw (see WrongSizedFrameFailsUnlessSkipped).
  r = RunCli("replay " + dir + "/log.lcmlog -o " + dir + "/c.ply --no-publish --skip-bad-frames --no-refine");
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

TEST_F(BadLogs, FramesWithoutNearbyStatesAreSkippedAndCounted) {
  const std::string dir = Write("sparse", false, false, true);
  // --no-refine: these frames hold no claw (see WrongSizedFrameFailsUnlessSkipped).
  const auto r = RunCli("replay " + dir + "/log.lcmlog -o " + dir + "/c.ply --no-publish --json --no-refine");
  // One state per frame, 33 ms apart, before the frame: the next state
  // brackets the frame within the 50 ms gap for all but the last frame.
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("\"frames_skipped_no_pose\": 1"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace graspfill
