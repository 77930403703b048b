// SPDX-License-Identifier: BSD-3-Clause
// --mesh-out end to end: synth -> replay --mesh-out on the e2e shapes (one
// format each), the mesh read back from the file: watertight by Open3D's
// test, within the triangle cap, holding every point of the repaired cloud
// replay wrote within the deviation it states (the test's own measure), its
// surface near the cloud, and the CLI's reported deviation matching the
// test's own measurement. Then the convex hull, repair --mesh-out,
// determinism, and bad input.
#include <gtest/gtest.h>
#include <open3d/core/Tensor.h>
#include <open3d/t/geometry/RaycastingScene.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli_runner.hpp"
#include "graspfill/core/percentile.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "graspfill/mesh/nearest_distances.hpp"
#include "open3d_watertight.hpp"

namespace graspfill {
namespace {

using testing::RunCli;
using testing::ScratchDir;

// The default cap (--mesh-max-triangles, mesh::PlannerMeshConfig).
constexpr size_t kMaxTriangles = 5000;
// The decimated mesh's surface to the cloud: a regression guard over what
// these shapes give today (p95 1.13-1.33 mm; docs/collision-mesh.md). The
// dense mesh alone is within 1.3 mm (p95) too, but leaves half the points
// outside.
constexpr double kSurfaceP95M = 0.002;
constexpr double kSurfaceMaxM = 0.008;

struct Case {
  std::string shape;
  std::string claw;
  std::string grasp;
  std::string format;
};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.shape << "/" << c.claw << "/" << c.grasp << "/" << c.format;
}

// Points of `cloud` outside `m` by more than `bound_m`: those farther from
// its surface (Open3D's distance query) and outside by the winding number.
// (Not mesh::OutsideDistances, the code under test; nor Open3D's occupancy,
// whose ray casts hit nothing in Debian's Open3D 0.16.)
int PointsOutsideBeyond(const TriangleMesh& m, const ObjectCloud& cloud, double bound_m) {
  namespace core = open3d::core;
  std::vector<float> v, q;
  std::vector<uint32_t> t;
  for (const Eigen::Vector3f& x : m.vertices) v.insert(v.end(), {x.x(), x.y(), x.z()});
  for (const Eigen::Vector3i& x : m.triangles) {
    t.insert(t.end(),
             {static_cast<uint32_t>(x[0]), static_cast<uint32_t>(x[1]), static_cast<uint32_t>(x[2])});
  }
  for (const Eigen::Vector3f& x : cloud.points_G) q.insert(q.end(), {x.x(), x.y(), x.z()});
  const auto rows = [](const auto& a) { return static_cast<int64_t>(a.size() / 3); };
  open3d::t::geometry::RaycastingScene scene;
  scene.AddTriangles(core::Tensor(v, {rows(v), 3}, core::Float32),
                     core::Tensor(t, {rows(t), 3}, core::UInt32));
  const core::Tensor query(q, {rows(q), 3}, core::Float32);
  const core::Tensor distance = scene.ComputeDistance(query).Contiguous();
  int beyond = 0;
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (distance.GetDataPtr<float>()[i] <= bound_m) continue;
    beyond += mesh::WindingNumber(m, cloud.points_G[i].cast<double>()) < 0.5;
  }
  return beyond;
}

// Merged first: an STL repeats each vertex per triangle.
bool Watertight(const TriangleMesh& m) { return testing::Open3dWatertight(m, true); }

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

TEST_P(MeshE2E, WatertightUnderTheCapAndHoldingTheRepairedCloud) {
  const Case& c = GetParam();
  const std::string dir = ScratchDir("e2e_mesh_" + c.shape + "_" + c.claw + "_" + c.grasp);
  const auto synth = RunCli("synth --shape " + c.shape + " --claw " + c.claw + " --grasp " + c.grasp +
                            " --seed 7 -o " + dir);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const std::string mesh_path = dir + "/mesh." + c.format;
  const auto replay = RunCli("replay " + dir + "/recording.lcmlog -o " + dir + "/cloud.ply --claw " + c.claw +
                             " --no-publish --json --mesh-out " + mesh_path);
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  const nlohmann::json report = JsonOf(replay.output)["mesh"];

  const ObjectCloud cloud = io::ReadCloudPly(dir + "/cloud.ply");
  const TriangleMesh mesh = io::ReadMesh(mesh_path);
  EXPECT_TRUE(Watertight(mesh));
  EXPECT_EQ(report["triangles"].get<size_t>(), mesh.triangles.size());
  EXPECT_LE(mesh.triangles.size(), kMaxTriangles);
  EXPECT_TRUE(report["closed"].get<bool>());
  EXPECT_TRUE(report["watertight"].get<bool>());
  EXPECT_EQ(report["kind"], "decimated");
  // Every point inside or within the stated deviation, by the test's own
  // measure; outside at all only the few the dense mesh drops as stray
  // skins (at most 1 in 1,000 points).
  const double stated_mm = report["deviation_mm"].get<double>();
  EXPECT_LE(report["outside_mm"]["points"].get<size_t>(), cloud.size() / 1000);
  EXPECT_EQ(report["outside_mm"]["p99"].get<double>(), 0.0);
  EXPECT_EQ(PointsOutsideBeyond(mesh, cloud, stated_mm * 1e-3 + 1e-6), 0);

  // The mesh's surface to the cloud, measured here from the files.
  const mesh::SurfaceSamples samples = mesh::SampleSurface(mesh, 100000, 11);
  const std::vector<double> mesh_to_cloud = mesh::NearestDistances(samples.points, cloud.points_G);
  const double p95 = Percentile(mesh_to_cloud, 95.0);
  std::printf(
      "%s/%s/%s: %zu triangles, mesh to cloud p95 %.3f mm (reported %.3f), deviation "
      "%.3f mm\n",
      c.shape.c_str(), c.claw.c_str(), c.grasp.c_str(), mesh.triangles.size(), p95 * 1e3,
      report["surface_to_cloud_mm"]["p95"].get<double>(), stated_mm);
  RecordProperty("surface_to_cloud_p95_mm", std::to_string(p95 * 1e3));
  EXPECT_LT(p95, kSurfaceP95M);
  EXPECT_LT(report["surface_to_cloud_mm"]["max"].get<double>(), kSurfaceMaxM * 1e3);
  // What the CLI reports is the same measurement on other samples: within
  // 0.05 mm, or between the 94.5th and 95.5th percentiles of these samples
  // (a p95 of 100k samples strays ~0.07% in rank: this is ~7 of those),
  // which is wider where the p95 lies in the sparse tail of far samples (a
  // claw hole left open, the top's cap).
  const double reported_mm = report["surface_to_cloud_mm"]["p95"].get<double>();
  const double band_lo_mm = Percentile(mesh_to_cloud, 94.5) * 1e3 - 0.05;
  const double band_hi_mm = Percentile(mesh_to_cloud, 95.5) * 1e3 + 0.05;
  EXPECT_TRUE(reported_mm >= band_lo_mm && reported_mm <= band_hi_mm)
      << "reported p95 " << reported_mm << " mm, these samples' 94.5-95.5th percentiles (+-0.05 mm) "
      << band_lo_mm << " .. " << band_hi_mm << " mm";
}

INSTANTIATE_TEST_SUITE_P(Shapes, MeshE2E,
                         ::testing::Values(Case{"cuboid", "three-finger", "top-straight", "stl"},
                                           Case{"triangular-prism", "three-finger", "top-straight", "obj"},
                                           Case{"cylinder", "three-finger", "top-straight", "ply"},
                                           Case{"sphere", "three-finger", "top-straight", "stl"},
                                           Case{"elliptic-cylinder", "parallel", "top-straight", "obj"},
                                           Case{"ellipsoid", "three-finger", "top-straight", "ply"}),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           std::string name =
                               info.param.shape + "_" + info.param.claw + "_" + info.param.grasp;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

// repair --mesh-out on the bundled recording's fused cloud: the same
// checks, and the same bytes on a second run.
TEST(MeshE2ERepair, RepairWritesTheSameWatertightMeshTwice) {
  const std::string dir = ScratchDir("e2e_mesh_repair");
  const auto fused = RunCli("replay " GRASPFILL_SOURCE_DIR "/replay/default/recording.lcmlog -o " + dir +
                            "/fused.ply --no-repair --no-publish");
  ASSERT_EQ(fused.exit_code, 0) << fused.output;
  for (const char* name : {"a.obj", "b.obj"}) {
    const auto r =
        RunCli("repair " + dir + "/fused.ply -o " + dir + "/" + name + ".ply --mesh-out " + dir + "/" + name);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("collision mesh: "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("deviation: mesh to cloud"), std::string::npos) << r.output;
  }
  const std::string a = ReadBytes(dir + "/a.obj");
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, ReadBytes(dir + "/b.obj"));
  EXPECT_TRUE(Watertight(io::ReadMesh(dir + "/a.obj")));
}

// --mesh-convex-hull under a cap the cloud's hull fits: convex, watertight,
// every point inside; then the mesh's flags out of range or alone.
TEST(MeshE2EHull, ConvexHullHoldsEveryPointAndTheFlagsAreChecked) {
  const std::string dir = ScratchDir("e2e_mesh_hull");
  const std::string log = GRASPFILL_SOURCE_DIR "/replay/default/recording.lcmlog";
  auto r = RunCli("replay " + log + " -o " + dir + "/cloud.ply --no-publish --json --mesh-out " + dir +
                  "/hull.obj --mesh-convex-hull --mesh-max-triangles 3000");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json report = JsonOf(r.output)["mesh"];
  EXPECT_EQ(report["kind"], "convex_hull");
  const TriangleMesh hull = io::ReadMesh(dir + "/hull.obj");
  EXPECT_LE(hull.triangles.size(), 3000u);
  EXPECT_TRUE(Watertight(hull));
  EXPECT_LT(report["deviation_mm"].get<double>(), 0.001);
  EXPECT_EQ(PointsOutsideBeyond(hull, io::ReadCloudPly(dir + "/cloud.ply"), 1e-6), 0);

  r = RunCli("replay " + log + " -o " + dir + "/c2.ply --mesh-out " + dir + "/m.ply --mesh-max-triangles 5");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--mesh-max-triangles '5': out of range"), std::string::npos) << r.output;
  r = RunCli("repair " + dir + "/cloud.ply -o " + dir + "/c3.ply --mesh-convex-hull");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("need --mesh-out"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/c3.ply"));
}

TEST(MeshE2EBadInput, UnknownExtensionSameAsCloudAndExistingFilesAreRefused) {
  const std::string dir = ScratchDir("e2e_mesh_bad");
  const std::string log = GRASPFILL_SOURCE_DIR "/replay/default/recording.lcmlog";
  auto r = RunCli("replay " + log + " -o " + dir + "/cloud.ply --mesh-out " + dir + "/mesh.vrml");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--mesh-out '" + dir + "/mesh.vrml': unknown extension (use .ply, .stl or .obj)"),
            std::string::npos)
      << r.output;
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
