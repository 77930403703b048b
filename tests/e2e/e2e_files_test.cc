// SPDX-License-Identifier: BSD-3-Clause
// The files the commands write and read, through the real CLI (issue 36):
// a FIFO or a device given as an output is refused even with --force and
// stays what it was; a robot that reuses grasp ids keeps every grasp's
// model; a malformed PLY given to eval is a clean error, not a crash.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "graspfill/core/percentile.hpp"
#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/nearest_distances.hpp"
#include "sinks/lcm_log_writer.hpp"

namespace graspfill {
namespace {

namespace fs = std::filesystem;
using testing::RunCli;
using testing::ScratchDir;

// The file type at `path` (not following a link), 0 if nothing is there.
mode_t TypeAt(const std::string& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0 ? (st.st_mode & S_IFMT) : 0;
}

nlohmann::json JsonOf(const std::string& output) {
  return nlohmann::json::parse(output.substr(output.find('{')));
}

// Outputs that are not regular files: a FIFO (streamed to by no command),
// and a character device like /dev/null where this process may make one
// (root; not in every container). Replay and repair used to accept them
// with --force and replace them with a regular file at the end.
class SpecialOutputs : public ::testing::Test {
 protected:
  // One folder per test: ctest runs the two at once, and a shared folder
  // let one test's setup delete the other's special files mid-run.
  void SetUp() override {
    dir_ = ScratchDir(std::string("e2e_files_special_") +
                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  // Runs `command` (with {} standing for the output) on each special
  // output named *`ext`: exit 1, the reason named, the output still what it
  // was.
  void ExpectRefused(const std::string& command, const std::string& ext = ".ply") {
    struct Special {
      std::string path;
      std::string why;
    };
    std::vector<Special> specials;
    const std::string fifo = dir_ + "/fifo" + ext, null = dir_ + "/null" + ext;
    if (TypeAt(fifo) == 0) {
      ASSERT_EQ(::mkfifo(fifo.c_str(), 0666), 0) << std::strerror(errno);
    }
    specials.push_back({fifo, "is a FIFO (named pipe), not a regular file"});
    if (TypeAt(null) == S_IFCHR || ::mknod(null.c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0) {
      specials.push_back({null, "is a character device, not a regular file"});
    }
    for (const Special& special : specials) {
      const mode_t type = TypeAt(special.path);
      std::string args = command;
      args.replace(args.find("{}"), 2, special.path);
      const auto run = RunCli(args);
      EXPECT_EQ(run.exit_code, 1) << args << "\n" << run.output;
      EXPECT_NE(run.output.find("'" + special.path + "' " + special.why), std::string::npos) << args << "\n"
                                                                                             << run.output;
      EXPECT_EQ(TypeAt(special.path), type) << args;
    }
  }

  std::string dir_;
};

TEST_F(SpecialOutputs, ReplayRefusesThemEvenWithForce) {
  const std::string log = std::string(GRASPFILL_SOURCE_DIR) + "/replay/default/recording.lcmlog";
  ExpectRefused("replay " + log + " -o {} --force --no-publish");
  // --mesh-out too.
  ExpectRefused("replay " + log + " -o " + dir_ + "/cloud.ply --mesh-out {} --force --no-publish");
  EXPECT_FALSE(fs::exists(dir_ + "/cloud.ply"));  // refused before the replay
}

TEST_F(SpecialOutputs, RepairAndOtherCommandsRefuseThemEvenWithForce) {
  ASSERT_EQ(RunCli("synth --protocol paper --shape cylinder --points 3000 -o " + dir_ + "/in").exit_code, 0);
  ExpectRefused("repair " + dir_ + "/in/holey.ply -o {} --force");
  ExpectRefused("config --dump-defaults -o {} --force");
  ExpectRefused("claw three-finger -o {} --force");
  ExpectRefused("view " + dir_ + "/in/holey.ply -o {} --force", ".png");
}

// A copy of the log at `from` whose gripper states carry grasp_ids[k - 1]
// instead of grasp id k.
void RenumberGrasps(const std::string& from, const std::string& to, const std::vector<int64_t>& grasp_ids) {
  const io::ChannelNames channels;
  io::LcmLogReader in(from);
  rt::LcmLogWriter out(to);
  io::LogEvent event;
  while (in.Next(&event) == io::LogReadResult::kEvent) {
    if (event.channel == channels.gripper_state) {
      GripperState state;
      std::string error;
      ASSERT_TRUE(io::DecodeGripperState(event.data.data(), event.data.size(), Eigen::Isometry3d::Identity(),
                                         &state, &error))
          << error;
      ASSERT_GE(state.grasp_id, 1);
      ASSERT_LE(state.grasp_id, static_cast<int64_t>(grasp_ids.size()));
      state.grasp_id = grasp_ids[static_cast<size_t>(state.grasp_id - 1)];
      event.data = io::EncodeGripperState(state);
    }
    out.Write(event.channel, event.timestamp_us, event.data);
  }
  out.Close();
}

// A robot that numbers its grasps 1, 2, 1, 2: replay used to write the
// third grasp's model over the first's (with --force) or fail at its end on
// the file it had written itself (without). Every grasp keeps its model,
// each of its own object, under the names --json reports.
TEST(GraspIds, ReusedIdsKeepEveryGraspsModel) {
  const std::string dir = ScratchDir("e2e_files_grasp_ids");
  const auto synth = RunCli("synth --grasps cuboid,cylinder,sphere,cylinder --frames 10 --seed 5 -o " + dir);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  RenumberGrasps(dir + "/recording.lcmlog", dir + "/reused.lcmlog", {1, 2, 1, 2});
  const auto replay =
      RunCli("replay " + dir + "/reused.lcmlog -o " + dir + "/model.ply --json --no-publish --no-repair");
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  const nlohmann::json report = JsonOf(replay.output);
  ASSERT_EQ(report["grasps"].size(), 4u) << report.dump(2);
  const std::vector<int64_t> ids = {1, 2, 1, 2};
  const std::vector<std::string> shapes = {"cuboid", "cylinder", "sphere", "cylinder"};
  const std::vector<std::string> names = {"model.grasp1.ply", "model.grasp2.ply", "model.grasp1-2.ply",
                                          "model.ply"};
  std::set<std::string> bytes;
  for (size_t k = 0; k < 4; ++k) {
    const nlohmann::json& g = report["grasps"][k];
    EXPECT_EQ(g["grasp_id"].get<int64_t>(), ids[k]);
    const std::string path = g["output"].get<std::string>();
    EXPECT_EQ(path, dir + "/" + names[k]);
    std::ifstream in(path, std::ios::binary);
    bytes.insert(std::string(std::istreambuf_iterator<char>(in), {}));
    // Each model is of its own grasp's object: nearer its own ground
    // truth than the other shapes' (grasps 2 and 4 both hold a cylinder).
    const std::vector<Eigen::Vector3f> model = io::ReadCloudPly(path).points_G;
    ASSERT_GT(model.size(), 500u) << path;
    std::vector<double> median_mm;
    for (size_t truth = 0; truth < 4; ++truth) {
      const std::vector<double> d = mesh::NearestDistances(
          model, io::ReadCloudPly(dir + "/grasp" + std::to_string(truth + 1) + "/gt_cloud.ply").points_G);
      median_mm.push_back(1e3 * Percentile(d, 50.0));
    }
    for (size_t truth = 0; truth < 4; ++truth) {
      if (shapes[truth] == shapes[k]) continue;
      EXPECT_LT(median_mm[k], median_mm[truth]) << path << " against grasp " << truth + 1 << "'s truth";
    }
  }
  EXPECT_EQ(bytes.size(), 4u);  // four different files
  // Run again with --force: the same names, replaced, nothing else made.
  const auto again = RunCli("replay " + dir + "/reused.lcmlog -o " + dir +
                            "/model.ply --json --no-publish --no-repair --force");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(JsonOf(again.output)["grasps"][k]["output"].get<std::string>(), dir + "/" + names[k]);
  }
}

// The probe's 44-byte PLY: `graspfill eval` segfaulted in Open3D's reader.
TEST(EvalFiles, ACutPlyHeaderIsACleanError) {
  const std::string dir = ScratchDir("e2e_files_eval");
  const std::string cut = dir + "/cut.ply";
  {
    std::ofstream out(cut, std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\nobj_info";
  }
  ASSERT_EQ(fs::file_size(cut), 44u);
  const std::string gt = std::string(GRASPFILL_SOURCE_DIR) + "/replay/default/gt_cloud.ply";
  for (const std::string& args : {cut + " " + gt, gt + " " + cut}) {
    const auto run = RunCli("eval " + args);
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_NE(run.output.find("cannot read PLY '" + cut + "'"), std::string::npos) << run.output;
  }
}

}  // namespace
}  // namespace graspfill
