// SPDX-License-Identifier: BSD-3-Clause
// --mesh-out end to end: synth -> replay --mesh-out on the e2e shapes (one
// format each), the mesh read back from the file: watertight by Open3D's
// test, its surface within 1 mm (p95) of the repaired cloud replay wrote
// where that target is met (three of six; the others within 1.25 mm), never
// farther than the construction allows, covering the cloud, and the CLI's reported
// deviation matching the test's own measurement. Then repair --mesh-out,
// determinism, and bad input.
#include <gtest/gtest.h>
#include <open3d/geometry/TriangleMesh.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli_runner.hpp"
#include "graspfill/eval/metrics.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/synth/mesh_sampling.hpp"

namespace graspfill {
namespace {

using testing::RunCli;
using testing::ScratchDir;

constexpr double kTargetP95M = 0.001;  // the bound: 1 mm
// Where the target is missed (docs/measurements/2026-12-03-collision-mesh.md:
// the cuboid, 1.28 mm): a regression
// guard 0.3 mm above it. (The cuboid's mesh was 1.14 mm from its cloud
// until its mirrored top was stretched to the evidence's rather than cut
// under it; the mesh is now closer to the truth, p95 1.42 -> 1.07 mm, and
// the cloud no longer holds a second cap 1-2 mm under the first, but a
// claw hole left open and the stretched band are sparser.)
constexpr double kNearTargetP95M = 0.0013;
// What the construction guarantees anywhere: every mesh vertex lies on a
// grid edge with a node in the fill band, i.e. within that band plus a cell
// of a point (CollisionMeshConfig defaults: 5 + 1 cells of 2 mm).
constexpr double kConstructionBoundM = 0.012;

struct Case {
  std::string shape;
  std::string claw;
  std::string grasp;
  std::string format;
  // Whether the 1 mm target holds here; where not,
  // docs/measurements/2026-12-03-collision-mesh.md gives the
  // measured p95 and the test holds the construction's bound.
  bool meets_target;
};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.shape << "/" << c.claw << "/" << c.grasp << "/" << c.format;
}

bool Watertight(const TriangleMesh& m) {
  open3d::geometry::TriangleMesh o;
  for (const Eigen::Vector3f& v : m.vertices) o.vertices_.push_back(v.cast<double>());
  o.triangles_ = m.triangles;
  // An STL repeats each vertex per triangle: merge them (by position) first.
  o.RemoveDuplicatedVertices();
  return o.IsWatertight();
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The JSON object a command printed (stdout and stderr are merged: the
// JSON starts at the first '{' at the start of a line).
nlohmann::json JsonOf(const std::string& output) {
  const size_t start = output.rfind("\n{") == std::string::npos ? output.find('{') : output.find("\n{") + 1;
  return nlohmann::json::parse(output.substr(start));
}

class MeshE2E : public ::testing::TestWithParam<Case> {};

TEST_P(MeshE2E, WatertightAndWithinAMillimetreOfTheRepairedCloud) {
  const Case& c = GetParam();
  const std::string dir = ScratchDir("e2e_mesh_" + c.shape + "_" + c.claw + "_" + c.grasp);
  const auto synth = RunCli("synth --shape " + c.shape + " --claw " + c.claw + " --grasp " +
                            c.grasp + " --seed 7 -o " + dir);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const std::string mesh_path = dir + "/mesh." + c.format;
  const auto replay = RunCli("replay " + dir + "/recording.lcmlog -o " + dir + "/cloud.ply --claw " +
                             c.claw + " --no-publish --json --mesh-out " + mesh_path);
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  const nlohmann::json report = JsonOf(replay.output)["mesh"];

  const ObjectCloud cloud = io::ReadCloudPly(dir + "/cloud.ply");
  const TriangleMesh mesh = io::ReadMesh(mesh_path);
  EXPECT_TRUE(Watertight(mesh));
  EXPECT_EQ(report["triangles"].get<size_t>(), mesh.triangles.size());
  EXPECT_TRUE(report["closed"].get<bool>());

  // The mesh's surface to the cloud, measured here from the files.
  const synth::SurfaceSamples samples = synth::SampleSurface(mesh, 100000, 11);
  const std::vector<double> mesh_to_cloud = eval::NearestDistances(samples.points, cloud.points_G);
  const double p95 = eval::Percentile(mesh_to_cloud, 95.0);
  std::printf("%s/%s/%s: %zu triangles, mesh to cloud p95 %.3f mm (reported %.3f), cloud to mesh "
              "p95 %.3f mm\n", c.shape.c_str(), c.claw.c_str(), c.grasp.c_str(),
              mesh.triangles.size(), p95 * 1e3, report["surface_to_cloud_mm"]["p95"].get<double>(),
              report["cloud_to_surface_mm"]["p95"].get<double>());
  RecordProperty("surface_to_cloud_p95_mm", std::to_string(p95 * 1e3));
  EXPECT_LT(p95, c.meets_target ? kTargetP95M : kNearTargetP95M);
  EXPECT_LT(report["surface_to_cloud_mm"]["max"].get<double>(), kConstructionBoundM * 1e3);
  // What the CLI reports is the same measurement on other samples: within
  // 0.05 mm, or between the 94.5th and 95.5th percentiles of these samples
  // (a p95 of 100k samples strays ~0.07% in rank: this is ~7 of those),
  // which is wider where the p95 lies in the sparse tail of far samples (a
  // claw hole left open, the top's cap).
  const double reported_mm = report["surface_to_cloud_mm"]["p95"].get<double>();
  const double band_lo_mm = eval::Percentile(mesh_to_cloud, 94.5) * 1e3 - 0.05;
  const double band_hi_mm = eval::Percentile(mesh_to_cloud, 95.5) * 1e3 + 0.05;
  EXPECT_TRUE(reported_mm >= band_lo_mm && reported_mm <= band_hi_mm)
      << "reported p95 " << reported_mm << " mm, these samples' 94.5-95.5th percentiles (+-0.05 mm) "
      << band_lo_mm << " .. " << band_hi_mm << " mm";
  // The mesh covers the cloud: every point's distance to it is small.
  EXPECT_LT(report["cloud_to_surface_mm"]["p95"].get<double>(), 1.0);
}

INSTANTIATE_TEST_SUITE_P(
    Shapes, MeshE2E,
    ::testing::Values(Case{"cuboid", "three-finger", "top-straight", "stl", false},
                      Case{"triangular-prism", "three-finger", "top-straight", "obj", true},
                      Case{"cylinder", "three-finger", "top-straight", "ply", true},
                      Case{"sphere", "three-finger", "top-straight", "stl", true},
                      Case{"elliptic-cylinder", "parallel", "top-straight", "obj", true},
                      Case{"ellipsoid", "three-finger", "top-straight", "ply", true}),
    [](const ::testing::TestParamInfo<Case>& info) {
      std::string name = info.param.shape + "_" + info.param.claw + "_" + info.param.grasp;
      std::replace(name.begin(), name.end(), '-', '_');
      return name;
    });

// repair --mesh-out on the bundled recording's fused cloud: the same
// checks, and the same bytes on a second run.
TEST(MeshE2ERepair, RepairWritesTheSameWatertightMeshTwice) {
  const std::string dir = ScratchDir("e2e_mesh_repair");
  const auto fused = RunCli("replay " GRASPFILL_SOURCE_DIR "/replay/default/recording.lcmlog -o " +
                            dir + "/fused.ply --no-repair --no-publish");
  ASSERT_EQ(fused.exit_code, 0) << fused.output;
  for (const char* name : {"a.obj", "b.obj"}) {
    const auto r = RunCli("repair " + dir + "/fused.ply -o " + dir + "/" + name + ".ply --mesh-out " +
                          dir + "/" + name);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("collision mesh: "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("deviation: mesh to cloud"), std::string::npos) << r.output;
  }
  const std::string a = ReadBytes(dir + "/a.obj");
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, ReadBytes(dir + "/b.obj"));
  EXPECT_TRUE(Watertight(io::ReadMesh(dir + "/a.obj")));
}

TEST(MeshE2EBadInput, UnknownExtensionSameAsCloudAndExistingFilesAreRefused) {
  const std::string dir = ScratchDir("e2e_mesh_bad");
  const std::string log = GRASPFILL_SOURCE_DIR "/replay/default/recording.lcmlog";
  auto r = RunCli("replay " + log + " -o " + dir + "/cloud.ply --mesh-out " + dir + "/mesh.vrml");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--mesh-out '" + dir + "/mesh.vrml': unknown extension (use .ply, .stl or .obj)"),
            std::string::npos) << r.output;
  r = RunCli("replay " + log + " -o " + dir + "/cloud.ply --mesh-out " + dir + "/cloud.ply");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("is the cloud's output (-o) too"), std::string::npos) << r.output;
  r = RunCli("repair " + log + " -o " + dir + "/out.ply --mesh-out " + dir + "/mesh");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("unknown extension"), std::string::npos) << r.output;

  // An existing mesh file is kept without --force, before any work.
  const std::string mesh = dir + "/mesh.stl";
  std::ofstream(mesh) << "keep me";
  r = RunCli("replay " + log + " -o " + dir + "/cloud.ply --mesh-out " + mesh);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("pass --force to overwrite it"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/cloud.ply"));
  EXPECT_EQ(ReadBytes(mesh), "keep me");
  r = RunCli("replay " + log + " -o " + dir + "/cloud.ply --no-publish --mesh-out " + mesh + " --force");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(Watertight(io::ReadMesh(mesh)));
}

}  // namespace
}  // namespace graspfill
