// SPDX-License-Identifier: BSD-3-Clause
// The planner-side examples (examples/) read what graspfill published: the
// bundled recording is replayed with its cloud logged by LCM's file://
// provider, and the C++ subscriber, the Java subscriber, the Python log
// reader and the Python module's subscriber must each print the summary
// graspfill's own decoder gives for that cloud, whose points and provenance
// are those of the PLY replay wrote.
#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli_runner.hpp"
#include "graspfill/io/collision_mesh_message.hpp"
#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/io/ply.hpp"

namespace graspfill {
namespace {

using testing::CliResult;
using testing::RunCli;
using testing::ScratchDir;

// Runs a shell command line; stdout and stderr together.
CliResult RunLine(const std::string& command) { return testing::RunShell(command + " 2>&1"); }

// The examples' summary line, written here from graspfill's own decoding.
std::string Summary(const ObjectCloud& c) {
  std::array<long long, 3> by{0, 0, 0};
  for (Provenance p : c.provenance) ++by[static_cast<int>(p)];
  // The added points above a coin flip.
  long long trusted = 0;
  for (size_t i = 0; i < c.size(); ++i)
    trusted += c.provenance[i] != Provenance::kObserved && c.confidence[i] > 0.5f;
  char line[256];
  std::snprintf(line, sizeof(line),
                "seq=%lld utime=%lld grasp=%lld final=%d points=%zu observed=%lld surface=%lld "
                "symmetry=%lld holes=%zu unobserved=%d trusted=%lld\n",
                static_cast<long long>(c.seq), static_cast<long long>(c.utime),
                static_cast<long long>(c.grasp_id), c.is_final ? 1 : 0, c.size(), by[0], by[1], by[2],
                c.holes.size(),
                static_cast<int>(std::count_if(c.holes.begin(), c.holes.end(),
                                               [](const HoleSummary& h) { return h.unobserved; })),
                trusted);
  return line;
}

class ExamplesTest : public ::testing::Test {
 protected:
  // CTest runs each test as a process of its own, in parallel: a folder
  // for each.
  static void SetUpTestSuite() {
    dir_ = ScratchDir("examples_" + std::to_string(getpid()));
    bus_log_ = dir_ + "/bus.lcmlog";
    const CliResult replay = RunCli("replay " GRASPFILL_SOURCE_DIR "/replay/default/recording.lcmlog -o " +
                                    dir_ + "/cloud.ply --lcm-url 'file://" + bus_log_ + "?mode=w'");
    ASSERT_EQ(replay.exit_code, 0) << replay.output;

    // graspfill's decoding of the one cloud on the bus.
    io::LcmLogReader reader(bus_log_);
    io::LogEvent event;
    int clouds = 0;
    while (reader.Next(&event) == io::LogReadResult::kEvent) {
      if (event.channel != "GRASPFILL_OBJECT_CLOUD") continue;
      std::string error;
      ASSERT_TRUE(io::DecodeObjectCloud(event.data.data(), event.data.size(), &published_, &error)) << error;
      ++clouds;
    }
    ASSERT_EQ(clouds, 1);
    expected_ = Summary(published_);
  }

  static void TearDownTestSuite() { std::filesystem::remove_all(dir_); }

  static std::string dir_;
  static std::string bus_log_;
  static ObjectCloud published_;
  static std::string expected_;
};
std::string ExamplesTest::dir_;
std::string ExamplesTest::bus_log_;
ObjectCloud ExamplesTest::published_;
std::string ExamplesTest::expected_;

TEST_F(ExamplesTest, BusCarriesTheWrittenModelWithRepairedPoints) {
  const ObjectCloud written = io::ReadCloudPly(dir_ + "/cloud.ply");
  ASSERT_EQ(published_.size(), written.size());
  EXPECT_EQ(published_.provenance, written.provenance);
  // Every provenance count the examples print is exercised.
  size_t observed = 0;
  for (Provenance p : written.provenance) observed += p == Provenance::kObserved;
  EXPECT_GT(observed, 1000u);
  EXPECT_LT(observed, written.size());
}

TEST_F(ExamplesTest, CppSubscriberPrintsThePublishedCloud) {
  const CliResult r = RunLine(std::string(EXAMPLE_CPP_SUBSCRIBER) + " 'file://" + bus_log_ + "?speed=0'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output, expected_);
}

TEST_F(ExamplesTest, CppSubscriberFailsAtTheLogsEndWithoutEnoughClouds) {
  const CliResult r = RunLine(std::string(EXAMPLE_CPP_SUBSCRIBER) + " 'file://" + bus_log_ +
                              "?speed=0' --count 2 --timeout-s 20");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find(expected_), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("1 of 2 clouds"), std::string::npos) << r.output;
}

std::string PythonReader(const std::string& args) {
  return "PYTHONPATH=" EXAMPLE_PYTHONPATH " " EXAMPLE_PYTHON " " GRASPFILL_SOURCE_DIR
         "/examples/python/read_object_clouds.py " +
         args;
}

TEST_F(ExamplesTest, PythonReaderPrintsThePublishedCloud) {
  const CliResult r = RunLine(PythonReader(bus_log_));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output, expected_);
}

TEST_F(ExamplesTest, PythonReaderRejectsBadLogsClearly) {
  // Not a log: the PLY.
  CliResult r = RunLine(PythonReader(dir_ + "/cloud.ply"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("not an LCM log"), std::string::npos) << r.output;
  // Cut short in the cloud's event.
  const std::string cut = dir_ + "/cut.lcmlog";
  std::filesystem::copy_file(bus_log_, cut, std::filesystem::copy_options::overwrite_existing);
  std::filesystem::resize_file(cut, std::filesystem::file_size(bus_log_) - 100);
  r = RunLine(PythonReader(cut));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("truncated event"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("Traceback"), std::string::npos) << r.output;
  // No cloud on the channel asked for.
  r = RunLine(PythonReader(bus_log_ + " --channel ELSEWHERE"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("no object_cloud_t on ELSEWHERE"), std::string::npos) << r.output;
}

// examples/python/subscribe_clouds.py: live through the Python module's
// Subscriber, fed the bus log by LCM's file:// provider.
TEST_F(ExamplesTest, PythonSubscriberPrintsThePublishedCloud) {
#ifndef EXAMPLE_PYTHON_MODULE
  GTEST_SKIP() << "the Python module is not built (GRASPFILL_BUILD_PYTHON)";
#else
  const CliResult r = RunLine("PYTHONPATH=" EXAMPLE_PYTHONPATH " " EXAMPLE_PYTHON " " GRASPFILL_SOURCE_DIR
                              "/examples/python/subscribe_clouds.py 'file://" +
                              bus_log_ + "?speed=0' --count 1 --timeout-s 30");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output, expected_);
#endif
}

TEST_F(ExamplesTest, JavaSubscriberPrintsThePublishedCloud) {
#ifndef EXAMPLE_JAVA
  GTEST_SKIP() << "Java bindings not built (no JDK or liblcm-java)";
#else
  const CliResult r =
      RunLine(std::string(EXAMPLE_JAVA) + " -cp " EXAMPLE_JAVA_CLASSPATH " ObjectCloudSubscriber 'file://" +
              bus_log_ + "?speed=0' --timeout-s 30");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // LCM's Java file provider may print an EOFException at the log's end.
  EXPECT_NE(r.output.find(expected_), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("seq="), r.output.rfind("seq=")) << r.output;
#endif
}

// replay --mesh-out publishes the model's collision mesh on its own
// channel; the C++ subscriber (--meshes) prints what graspfill's decoder
// reads of it, and that is the mesh the file holds.
TEST(ExamplesMeshTest, CppSubscriberPrintsThePublishedCollisionMesh) {
  const std::string dir = ScratchDir("examples_mesh_" + std::to_string(getpid()));
  const std::string bus_log = dir + "/bus.lcmlog";
  const CliResult replay =
      RunCli("replay " GRASPFILL_SOURCE_DIR "/replay/default/recording.lcmlog -o " + dir +
             "/cloud.ply --mesh-out " + dir + "/mesh.ply --lcm-url 'file://" + bus_log + "?mode=w'");
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  io::LcmLogReader reader(bus_log);
  io::LogEvent event;
  io::CollisionMeshMessage published;
  int meshes = 0;
  while (reader.Next(&event) == io::LogReadResult::kEvent) {
    if (event.channel != "GRASPFILL_COLLISION_MESH") continue;
    std::string error;
    ASSERT_TRUE(io::DecodeCollisionMesh(event.data.data(), event.data.size(), &published, &error)) << error;
    ++meshes;
  }
  ASSERT_EQ(meshes, 1);
  const TriangleMesh written = io::ReadMesh(dir + "/mesh.ply");
  EXPECT_EQ(published.mesh.triangles, written.triangles);
  EXPECT_EQ(published.mesh.vertices, written.vertices);
  EXPECT_LE(published.mesh.triangles.size(), 5000u);
  EXPECT_TRUE(published.watertight);

  char line[256];
  std::snprintf(line, sizeof(line),
                "mesh seq=%lld utime=%lld grasp=%lld kind=decimated watertight=1 vertices=%zu "
                "triangles=%zu deviation_mm=%.3f\n",
                static_cast<long long>(published.seq), static_cast<long long>(published.utime),
                static_cast<long long>(published.grasp_id), published.mesh.vertices.size(),
                published.mesh.triangles.size(), published.deviation_m * 1e3);
  const CliResult r =
      RunLine(std::string(EXAMPLE_CPP_SUBSCRIBER) + " 'file://" + bus_log + "?speed=0' --meshes");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output, line);
  std::filesystem::remove_all(dir);
}

// lcm-spy decodes the types it finds in the jars on CLASSPATH
// (docs/planner-bindings.md):
// started headless, it counts them before it fails to open its window.
TEST(LcmSpyTest, FindsEveryGraspfillTypeThroughClasspath) {
#ifndef EXAMPLE_JAVA
  GTEST_SKIP() << "Java bindings not built (no JDK or liblcm-java)";
#else
  int types = 0;
  for (const auto& entry : std::filesystem::directory_iterator(GRASPFILL_SOURCE_DIR "/lcmtypes")) {
    types += entry.path().extension() == ".lcm";
  }
  const CliResult r =
      RunLine("CLASSPATH=" EXAMPLE_TYPES_JAR " " EXAMPLE_JAVA " -Djava.awt.headless=true -cp " EXAMPLE_LCM_JAR
              " lcm.spy.Spy --lcm-url=memq://");
  EXPECT_NE(r.output.find("Found " + std::to_string(types) + " LCM types"), std::string::npos) << r.output;
#endif
}

}  // namespace
}  // namespace graspfill
