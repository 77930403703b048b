// SPDX-License-Identifier: BSD-3-Clause
// Self-describing recordings through the real CLI: `synth` writes a session
// description at the head of the log, `replay` takes the claw from it
// (a parallel-claw recording replays clean with no --claw), warns when
// --claw is not the recording's claw, and keeps today's default for logs
// without one; and every command rejects malformed numbers with exit 2.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "cloud_parts.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/nearest_distances.hpp"
#include "sinks/lcm_log_writer.hpp"

namespace graspfill {
namespace {

using testing::ObservedPoints;
using testing::RunCli;
using testing::SampleSurface;
using testing::ScratchDir;

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The JSON report in the CLI's output (stderr is mixed in: the outermost
// braces); not an object if it does not parse.
nlohmann::json ParseReport(const std::string& output) {
  const size_t first = output.find('{'), last = output.rfind('}');
  if (first == std::string::npos || last == std::string::npos || last < first) return {};
  return nlohmann::json::parse(output.substr(first, last - first + 1), nullptr, false);
}

struct ClawCount {
  size_t fused{0};      ///< fused (observed) points
  size_t claw_left{0};  ///< of them, on the claw: within 2 mm of it, > 2 mm from the object
};

// As e2e_shapes_test counts them; claw.ply is the posed claw in G.
ClawCount CountClawPoints(const std::string& dir, const std::string& cloud_ply) {
  const std::vector<Eigen::Vector3f> fused = ObservedPoints(io::ReadCloudPly(cloud_ply));
  const ObjectCloud gt = io::ReadCloudPly(dir + "/gt_cloud.ply");
  const std::vector<Eigen::Vector3f> claw = SampleSurface(io::ReadMesh(dir + "/claw.ply"), 0.001f);
  const std::vector<double> to_gt = mesh::NearestDistances(fused, gt.points_G);
  const std::vector<double> to_claw = mesh::NearestDistances(fused, claw);
  ClawCount count;
  count.fused = fused.size();
  for (size_t i = 0; i < fused.size(); ++i) count.claw_left += to_claw[i] < 0.002 && to_gt[i] > 0.002;
  std::printf("%s: %zu claw points of %zu\n", cloud_ply.c_str(), count.claw_left, count.fused);
  return count;
}

// A small box held by the parallel claw: 30 frames, no wall (a fast log,
// ~1 s), one per test (ctest runs the tests in parallel processes).
class ParallelRecording : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ScratchDir(std::string("session_parallel_") +
                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
    const auto synth = RunCli(
        "synth --shape cuboid --size 0.05x0.05x0.08 --claw parallel "
        "--frames 30 --wall-m 0 --seed 3 -o " +
        dir_);
    ASSERT_EQ(synth.exit_code, 0) << synth.output;
  }
  testing::CliResult Replay(const std::string& name, const std::string& flags) const {
    return RunCli("replay " + dir_ + "/recording.lcmlog -o " + dir_ + "/" + name +
                  " --no-repair --no-publish --json " + flags);
  }
  std::string dir_;
};

constexpr const char* kWrongClawWarning =
    "graspfill replay: warning: --claw three-finger differs from the claw this recording was "
    "made with (parallel, from its session description); using three-finger";

TEST_F(ParallelRecording, ReplaysWithItsOwnClawWithoutBeingTold) {
  const auto r = Replay("own.ply", "");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
  const nlohmann::json report = ParseReport(r.output);
  ASSERT_TRUE(report.is_object()) << r.output;
  EXPECT_EQ(report["claw"]["name"], "parallel");
  EXPECT_EQ(report["claw"]["from"], "session description");
  EXPECT_EQ(report["session"]["software_version"].get<std::string>().rfind("graspfill ", 0), 0u);
  EXPECT_EQ(report["session"]["descriptions"], 1);
  const ClawCount count = CountClawPoints(dir_, dir_ + "/own.ply");
  ASSERT_GT(count.fused, 5000u);
  EXPECT_LT(count.claw_left, 0.001 * count.fused) << count.claw_left << " claw points";
}

TEST_F(ParallelRecording, AWrongClawIsWarnedAboutAndShowsInTheCloud) {
  const auto r = Replay("wrong.ply", "--claw three-finger");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(kWrongClawWarning), std::string::npos) << r.output;
  EXPECT_EQ(ParseReport(r.output)["claw"]["from"], "command line");
  // What the warning is about: the parallel fingers were not cut out
  // (the issue measured 3,631 of 11,544 points).
  const ClawCount count = CountClawPoints(dir_, dir_ + "/wrong.ply");
  EXPECT_GT(count.claw_left, 0.05 * count.fused) << count.claw_left << " claw points";
}

TEST_F(ParallelRecording, TheSameClawGivenAnyWayIsNotWarnedAbout) {
  const auto own = Replay("same_own.ply", "");
  ASSERT_EQ(own.exit_code, 0) << own.output;
  for (const std::string& spec : {std::string("parallel"), dir_ + "/claw/claw.json"}) {
    SCOPED_TRACE(spec);
    const auto r = Replay("same.ply", "--force --claw " + spec);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
    EXPECT_EQ(ReadText(dir_ + "/same.ply"), ReadText(dir_ + "/same_own.ply"));
  }
}

// The log with its session description replaced (or dropped: nullptr).
void RewriteSession(const std::string& from, const std::string& to, const io::SessionDescription* session) {
  const io::ChannelNames channels;
  lcm::LogFile in(from, "r");
  ASSERT_TRUE(in.good());
  rt::LcmLogWriter out(to, /*overwrite=*/true);
  int replaced = 0;
  while (const lcm::LogEvent* event = in.readNextEvent()) {
    if (event->channel == channels.session) {
      ++replaced;
      if (session) out.Write(channels.session, event->timestamp, io::EncodeSessionDescription(*session));
      continue;
    }
    const auto* data = static_cast<const uint8_t*>(event->data);
    out.Write(event->channel, event->timestamp, std::vector<uint8_t>(data, data + event->datalen));
  }
  EXPECT_EQ(replaced, 1);
}

TEST_F(ParallelRecording, ADescriptionClawInTheSessionIsUsedToo) {
  io::SessionDescription session;
  session.software_version = "someone else's recorder";
  session.claw_kind = io::SessionClawKind::kDescription;
  session.claw_name = "parallel";
  session.claw_text = ReadText(dir_ + "/claw/claw.json");
  session.claw_source = dir_ + "/claw/claw.json";  // its meshes beside it
  RewriteSession(dir_ + "/recording.lcmlog", dir_ + "/description.lcmlog", &session);
  // Its meshes are read from the local --claw-mesh-root only (issue 36),
  // not beside the claw_source the log names.
  const auto r = RunCli("replay " + dir_ + "/description.lcmlog -o " + dir_ +
                        "/description.ply --force --no-repair --no-publish --json "
                        "--claw-mesh-root " +
                        dir_ + "/claw");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json report = ParseReport(r.output);
  EXPECT_EQ(report["claw"]["from"], "session description");
  EXPECT_EQ(report["claw"]["name"], "description 'parallel' (" + session.claw_source + ")");
  const ClawCount count = CountClawPoints(dir_, dir_ + "/description.ply");
  ASSERT_GT(count.fused, 5000u);
  EXPECT_LT(count.claw_left, 0.001 * count.fused) << count.claw_left << " claw points";

  // A session asking for a voxel out of range is refused, not obeyed.
  session.voxel_m = 1.5;
  RewriteSession(dir_ + "/recording.lcmlog", dir_ + "/voxel.lcmlog", &session);
  const auto bad =
      RunCli("replay " + dir_ + "/voxel.lcmlog -o " + dir_ + "/voxel.ply --force --no-repair --no-publish");
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(bad.output.find("asks for a voxel of 1.5"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/voxel.ply"));
}

TEST_F(ParallelRecording, WithoutASessionDescriptionTheDefaultClawIsUsedAsBefore) {
  RewriteSession(dir_ + "/recording.lcmlog", dir_ + "/bare.lcmlog", nullptr);
  const auto r = RunCli("replay " + dir_ + "/bare.lcmlog -o " + dir_ +
                        "/bare.ply --force --no-repair --no-publish --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
  const nlohmann::json report = ParseReport(r.output);
  EXPECT_EQ(report["claw"]["name"], "three-finger");
  EXPECT_EQ(report["claw"]["from"], "default");
  EXPECT_TRUE(report["session"].is_null());
  const auto wrong = Replay("bare_wrong.ply", "--force --claw three-finger");
  ASSERT_EQ(wrong.exit_code, 0) << wrong.output;
  EXPECT_EQ(ReadText(dir_ + "/bare.ply"), ReadText(dir_ + "/bare_wrong.ply"));
}

// The 10x10x20 cm cuboid held in the middle gets longer fingers than the
// built-in's: --claw parallel is then not the recording's claw either.
TEST(SessionE2E, LengthenedFingersAreNotTheBuiltinClaw) {
  const std::string dir = ScratchDir("session_long_fingers");
  const auto synth = RunCli(
      "synth --shape cuboid --size 0.10x0.10x0.20 --claw parallel --grasp "
      "middle-straight --frames 8 --wall-m 0 -o " +
      dir);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const auto own =
      RunCli("replay " + dir + "/recording.lcmlog -o " + dir + "/own.ply --no-repair --no-publish");
  ASSERT_EQ(own.exit_code, 0) << own.output;
  EXPECT_EQ(own.output.find("warning"), std::string::npos) << own.output;
  EXPECT_NE(own.output.find("claw: parallel (as recorded: finger_length_m"), std::string::npos) << own.output;
  const auto given = RunCli("replay " + dir + "/recording.lcmlog -o " + dir +
                            "/given.ply --no-repair --no-publish --claw parallel");
  ASSERT_EQ(given.exit_code, 0) << given.output;
  EXPECT_NE(given.output.find("warning: --claw parallel differs from the claw this recording "
                              "was made with (parallel (as recorded: finger_length_m"),
            std::string::npos)
      << given.output;
}

// Numeric options: the whole text a number in range, else exit 2 with the
// option, the text and what was expected.
TEST(SessionE2E, NumbersAreParsedStrictlyEverywhere) {
  const std::string dir = ScratchDir("strict_numbers");
  const std::string log = std::string(GRASPFILL_SOURCE_DIR) + "/replay/default/recording.lcmlog";
  struct Case {
    std::string args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"replay " + log + " -o " + dir + "/x.ply --voxel-m abc", "--voxel-m 'abc': not a number"},
      {"replay " + log + " -o " + dir + "/x.ply --voxel-m 1.5",
       "--voxel-m '1.5': out of range, expected 0.0005..0.01 m"},
      {"replay " + log + " -o " + dir + "/x.ply --voxel-m 0.002mm", "--voxel-m '0.002mm': not a number"},
      {"synth --shape cuboid --frames 12x -o " + dir + "/s", "--frames '12x': not an integer"},
      {"synth --shape cuboid --wall-m nan -o " + dir + "/s",
       "--wall-m 'nan': out of range, expected 0..100 m"},
      {"live --depth-from-lcm --publish-every 3.5", "--publish-every '3.5': not an integer"},
      {"live --depth-from-lcm --duration-s abc", "--duration-s 'abc': not a number"},
      {"live --depth-from-lcm --idle-exit-s -1", "--idle-exit-s '-1': out of range, expected 0..604800 s"},
      {"live --depth-from-lcm --heap-reserve-mb abc", "--heap-reserve-mb 'abc': not an integer"},
      {"bench live --heap-reserve-mb -1", "--heap-reserve-mb '-1': out of range, expected 0..65536"},
      {"bench " + log + " --repeat 0", "--repeat '0': out of range, expected 1..1000"},
      {"bench " + log + " --repeat x", "--repeat 'x': not an integer"},
      // bench repair, bench repair --pipeline and repair --up (were std::stoi/stod/istream).
      {"bench repair --points 2e4", "--points '2e4': not an integer"},
      {"bench repair --points 20000x", "--points '20000x': not an integer"},
      {"bench repair --points 10", "--points '10': out of range, expected 1000..5000000"},
      {"bench repair --seed -1", "--seed '-1': not an integer"},
      {"bench repair --top-cut 0.1x", "--top-cut '0.1x': not a number"},
      {"bench repair --top-cut 0.5", "--top-cut '0.5': out of range"},
      {"bench repair --top-cut nan", "--top-cut 'nan': out of range"},
      {"bench repair --pipeline --frames 12x", "--frames '12x': not an integer"},
      {"bench repair --pipeline --frames 5", "--frames '5': out of range, expected 10..3000"},
      {"bench repair --pipeline --repeat 0", "--repeat '0': out of range, expected 1..100"},
      {"bench repair --pipeline --mixed-pixels 2", "--mixed-pixels '2': out of range, expected 0..1"},
      {"bench repair --pipeline --wobble-mm", "--wobble-mm needs a value"},
      {"repair " + dir + "/in.ply -o " + dir + "/x.ply --up 0,0,1x", "--up '1x': not a number"},
      {"repair " + dir + "/in.ply -o " + dir + "/x.ply --up 0,0", "--up '0,0': expected X,Y,Z"},
      {"repair " + dir + "/in.ply -o " + dir + "/x.ply --up 0,0,0",
       "--up '0,0,0': a zero vector has no direction"},
      {"repair " + dir + "/in.ply -o " + dir + "/x.ply --up ' 1,0,0'", "--up ' 1': not a number"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const auto r = RunCli(c.args);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.ply"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/s"));
}

// --dump: a directory that is not there, or a file of the dump already
// there, is refused before any work, and the file is left as it was.
TEST(SessionE2E, BenchPipelineDumpRefusesAMissingDirectoryAndExistingFiles) {
  const std::string dir = ScratchDir("bench_dump");
  const auto missing = RunCli("bench repair --pipeline --case plum --dump " + dir + "/nothing");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("is not a directory"), std::string::npos) << missing.output;
  const std::string kept = dir + "/plum_evidence.ply";
  { std::ofstream(kept) << "mine"; }
  const auto taken = RunCli("bench repair --pipeline --case plum --dump " + dir);
  EXPECT_EQ(taken.exit_code, 1);
  EXPECT_NE(taken.output.find("exists (not overwritten)"), std::string::npos) << taken.output;
  std::ifstream in(kept);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "mine");
  EXPECT_FALSE(std::filesystem::exists(dir + "/plum_fused.ply"));
}

// The zoo under a sensor's artefacts: the tuna can with every edge pixel
// mixed (synth's flying pixels) leaves fused points off the can; with the
// depth edges dropped, none. (Clean, none is off: bench repair --pipeline
// --case tuna.)
TEST(SessionE2E, BenchPipelineRendersTheArtefactsAndDropsTheDepthEdges) {
  const auto fused_row = [](const std::string& flags) {
    const auto r = RunCli("bench repair --pipeline --case tuna --repeat 1 --json " + flags);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    const size_t first = r.output.find('['), last = r.output.rfind(']');
    if (first == std::string::npos || last == std::string::npos || last < first) return nlohmann::json();
    const nlohmann::json rows =
        nlohmann::json::parse(r.output.substr(first, last - first + 1), nullptr, false);
    return rows.is_array() && rows.size() == 1 ? rows[0] : nlohmann::json();
  };
  const nlohmann::json mixed = fused_row("--mixed-pixels 1");
  const nlohmann::json dropped = fused_row("--mixed-pixels 1 --reject-depth-edges");
  ASSERT_TRUE(mixed.is_object() && dropped.is_object());
  EXPECT_GT(mixed["fused_off_object_share"].get<double>(), 0.001);
  EXPECT_GT(mixed["fused_p99_mm"].get<double>(), 1.5);
  EXPECT_LT(dropped["fused_off_object_share"].get<double>(), 0.0005);
  EXPECT_LT(dropped["fused_p99_mm"].get<double>(), 1.0);
  EXPECT_LT(dropped["fused_points"].get<int>(), mixed["fused_points"].get<int>());
}

}  // namespace
}  // namespace graspfill
