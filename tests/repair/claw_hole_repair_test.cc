// SPDX-License-Identifier: BSD-3-Clause
// Step 7: claw holes of the paper's protocol (object frame = V: z up, the
// missing top at max z) filled from the local fit (default), its thin-plate
// fallback and from Poisson (the paper's setting and the local variant).
// Hole boundaries are built geometrically (the rim
// of each finger patch), since steps 1-6 are separate units.
#include "claw_hole_repair.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>
#include <string>

#include "boundary_fixtures.hpp"
#include "eval/metrics.hpp"
#include "fill_checks.hpp"
#include "graspfill/core/percentile.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "graspfill/mesh/nearest_distances.hpp"
#include "neighbor_index.hpp"
#include "synth/paper_protocol.hpp"
#include "synth/shapes.hpp"

namespace graspfill::repair {
namespace {

using synth::GraspWay;
using synth::PaperProtocolConfig;
using synth::Shape;
using testing::kCoverD;
using testing::kCoverFraction;
using testing::kSurfaceFraction;
using testing::kSurfaceTolM;
using testing::MeanNn;
using testing::Ms;

struct Scene {
  PaperProtocolConfig config;
  synth::PaperProtocolCloud cloud;
  double top_z{0.0};
  testing::ProtocolHoles patches;  // the fingers' patches
  std::vector<HoleBoundary> holes;
  PointList dense_truth;  // ~300k points of the true surface
  double d{0.0};          // mean NN distance of the holey cloud
};

Scene MakeScene(Shape shape, GraspWay grasp, int num_points = 50000,
                const Eigen::Vector3d& size_m = Eigen::Vector3d::Zero()) {
  Scene s;
  s.config.shape = shape;
  s.config.grasp = grasp;
  s.config.size_m = size_m;
  s.config.random_pose = false;
  s.config.num_points = num_points;
  s.cloud = synth::MakePaperProtocolCloud(s.config);
  s.patches = testing::HolesOf(s.config, s.cloud.size_m);
  s.top_z = s.patches.top_z;
  // Each hole's boundary: the cloud points within 1.5 mm outside its patch
  // (what steps 2-6 deliver, up to order and the completion's points).
  for (size_t i = 0; i < s.patches.dirs.size(); ++i) {
    HoleBoundary hole;
    hole.kind = HoleKind::kClaw;
    hole.closed = true;
    for (const Eigen::Vector3f& p : s.cloud.holey) {
      if (testing::WithinPatch(s.patches, i, p, 0.0015)) {
        hole.points_V.push_back(p);
        hole.source_indices.push_back(-1);
      }
    }
    s.holes.push_back(hole);
  }
  const TriangleMesh mesh = synth::MakeShape(shape, s.cloud.size_m);
  s.dense_truth = mesh::SampleSurface(mesh, 300000, 99).points;
  s.d = MeanNn(s.cloud.holey);
  return s;
}

struct FillStats {
  double on_surface{0.0};      // fraction of added within kSurfaceTolM
  double p95_mm{0.0};          // 95th percentile of their distance
  double interior_cover{1.0};  // worst hole: interior truth covered by added
  double union_cover{1.0};     // worst hole: truth covered by cloud + added
};

FillStats Evaluate(const Scene& s, const PointList& added, double cover_m = 0.0) {
  if (cover_m <= 0.0) cover_m = kCoverD * s.d;
  FillStats st;
  const std::vector<double> dist = mesh::NearestDistances(added, s.dense_truth);
  st.on_surface = eval::FractionWithin(dist, kSurfaceTolM);
  st.p95_mm = 1e3 * Percentile(dist, 95.0);
  PointList both = s.cloud.holey;
  both.insert(both.end(), added.begin(), added.end());
  for (size_t i = 0; i < s.patches.dirs.size(); ++i) {
    PointList in_hole;
    for (const Eigen::Vector3f& p : s.cloud.ground_truth) {
      if (testing::WithinPatch(s.patches, i, p, 0.0) && p.z() <= s.top_z) in_hole.push_back(p);
    }
    if (in_hole.empty()) continue;
    const std::vector<double> to_cloud = mesh::NearestDistances(in_hole, s.cloud.holey);
    const std::vector<double> to_added = mesh::NearestDistances(in_hole, added);
    const std::vector<double> to_both = mesh::NearestDistances(in_hole, both);
    int interior = 0, interior_covered = 0;
    for (size_t i = 0; i < in_hole.size(); ++i) {
      if (to_cloud[i] <= cover_m) continue;
      ++interior;
      interior_covered += to_added[i] <= cover_m;
    }
    if (interior > 0) {
      st.interior_cover = std::min(st.interior_cover, interior_covered / double(interior));
    }
    st.union_cover = std::min(st.union_cover, eval::FractionWithin(to_both, cover_m));
  }
  return st;
}

void Print(const char* label, const Scene& s, const PointList& added, const FillStats& st, double ms) {
  std::printf(
      "[claw] %-34s cloud %zu pts, D %.2f mm: +%zu pts in %.1f ms; on surface %.3f "
      "(p95 %.2f mm), interior cover %.3f, union cover %.3f\n",
      label, s.cloud.holey.size(), 1e3 * s.d, added.size(), ms, st.on_surface, st.p95_mm, st.interior_cover,
      st.union_cover);
}

struct Fill {
  PointList added;
  FillStats st;
};

// Fills s's holes with `config` (and an index shared by the fill's
// steps), then evaluates the fill and prints it under `label`.
Fill FillHoles(const Scene& s, const std::string& label, const ClawRepairConfig& config = ClawRepairConfig{},
               double cover_m = 0.0) {
  const NeighborIndex index(s.cloud.holey);
  const auto t0 = std::chrono::steady_clock::now();
  Fill fill;
  fill.added = RepairClawHoles(s.cloud.holey, s.holes, config, nullptr, &index);
  const double ms = Ms(t0);
  fill.st = Evaluate(s, fill.added, cover_m);
  Print(label.c_str(), s, fill.added, fill.st, ms);
  return fill;
}

void ExpectGoodFill(const FillStats& st) {
  EXPECT_GE(st.on_surface, kSurfaceFraction);
  EXPECT_GE(st.interior_cover, kCoverFraction);
  EXPECT_GE(st.union_cover, kCoverFraction);
}

TEST(ClawHoleRepair, DefaultsValidateAndBadValuesThrow) {
  EXPECT_NO_THROW(ClawRepairConfig{}.Validate());
  EXPECT_NO_THROW(ClawRepairConfig::Paper().Validate());
  EXPECT_EQ(ClawRepairConfig::Paper().poisson_depth, 6);
  EXPECT_EQ(ClawRepairConfig::Paper().poisson_scale, 4.0);
  EXPECT_EQ(ClawRepairConfig::Paper().surface, ClawSurface::kPoisson);
  ClawRepairConfig c;
  c.polynomial_degree = 0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = {};
  c.local_margin_m = -1.0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = {};
  c.poisson_scale = 0.5;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = {};
  c.max_inside_outline_m = -0.001;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = {};
  c.max_inside_top_rim_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = {};
  c.max_outside_widest_m = -0.001;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  EXPECT_EQ(ClawRepairConfig::Paper().max_inside_top_rim_m, 0.0);
  EXPECT_EQ(ClawRepairConfig::Paper().max_outside_widest_m, 0.0);
}

// A 70 mm ball's top rim, 36 degrees from its pole and seen over three
// quarters of its turn, tilted like a fused one's (its height varies by 2 mm around it).
// Fills over the rim on the cap go; a wall rising past the rim, fills
// under it, and a cap fill where no rim point is near stay.
TEST(ClawHoleRepair, FillsOnTheTopAboveItsRimAreDropped) {
  const double radius = 0.035, polar = 36.0 * M_PI / 180.0;
  const auto on_sphere = [&](double polar_rad, double azimuth) {
    return Eigen::Vector3f(static_cast<float>(radius * std::sin(polar_rad) * std::cos(azimuth)),
                           static_cast<float>(radius * std::sin(polar_rad) * std::sin(azimuth)),
                           static_cast<float>(radius * std::cos(polar_rad)));
  };
  PointList rim;
  for (int k = 0; k < 91; ++k) {
    const double azimuth = -0.75 * M_PI + 1.5 * M_PI * k / 90.0;  // three quarters
    Eigen::Vector3f p = on_sphere(polar, azimuth);
    p.z() += 0.001f * static_cast<float>(std::sin(azimuth));
    rim.push_back(p);
  }
  const float rim_r = static_cast<float>(radius * std::sin(polar));
  PointList fills, kept;
  for (double a = -0.5; a <= 0.5; a += 0.1) {
    for (double cap_deg = 15.0; cap_deg <= 31.0; cap_deg += 4.0)
      fills.push_back(on_sphere(cap_deg * M_PI / 180.0, a));
    // A wall rising 2 mm past the rim, just outside and on the outline.
    for (const float dz : {0.0005f, 0.001f, 0.002f}) {
      kept.emplace_back(rim_r * static_cast<float>(std::cos(a)), rim_r * static_cast<float>(std::sin(a)),
                        rim[45].z() + 0.0015f + dz);
    }
    // Under the rim, deep inside its outline.
    kept.emplace_back(0.5f * rim_r * static_cast<float>(std::cos(a)),
                      0.5f * rim_r * static_cast<float>(std::sin(a)), rim[45].z() - 0.0015f);
  }
  // Inside the outline, but no rim point within 15 degrees of it.
  kept.emplace_back(-0.003f, 0.0f, static_cast<float>(radius) - 0.001f);
  const size_t cap_fills = fills.size();
  fills.insert(fills.end(), kept.begin(), kept.end());
  EXPECT_EQ(DropFillsOnTheTop(rim, 0.001, &fills), cap_fills);
  EXPECT_EQ(fills, kept);
  EXPECT_EQ(DropFillsOnTheTop(rim, 0.0, &fills), 0u);
  EXPECT_EQ(DropFillsOnTheTop(PointList(rim.begin(), rim.begin() + 2), 0.001, &fills), 0u);
  EXPECT_EQ(fills, kept);
}

TEST(ClawHoleRepair, BadInputThrowsAndEmptyInputIsANoOp) {
  const ClawRepairConfig config;
  EXPECT_TRUE(RepairClawHoles({}, {}, config).empty());
  PointList points = {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(0, 1, 0)};
  EXPECT_TRUE(RepairClawHoles(points, {}, config).empty());
  HoleBoundary hole;
  hole.points_V = points;
  // Too little support around the hole: skipped, not a crash.
  EXPECT_TRUE(RepairClawHoles(points, {hole}, config).empty());
  PointList bad = points;
  bad[1].x() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(RepairClawHoles(bad, {hole}, config), std::invalid_argument);
  const std::vector<Eigen::Vector3f> normals(2, Eigen::Vector3f::UnitZ());
  EXPECT_THROW(RepairClawHoles(points, {hole}, config, &normals), std::invalid_argument);
  const PointList other = points;
  const NeighborIndex index(other);
  EXPECT_THROW(RepairClawHoles(points, {hole}, config, nullptr, &index), std::invalid_argument);
}

// The default fill on a 50k-point protocol cloud (the target: the whole
// repair under 100 ms on 2 cores), median of 5 runs, with a shared index.
TEST(ClawHoleRepair, TimingOnTheProtocolCloud) {
  for (Shape shape : {Shape::kCylinder, Shape::kCuboid, Shape::kSphere}) {
    const Scene s = MakeScene(shape, GraspWay::kTopStraight, 66000);  // ~50k after the cuts
    auto t0 = std::chrono::steady_clock::now();
    const NeighborIndex index(s.cloud.holey);
    const double index_ms = Ms(t0);
    std::vector<double> ms, cpu_ms;
    size_t added = 0;
    for (int run = 0; run < 9; ++run) {
      t0 = std::chrono::steady_clock::now();
      const std::clock_t c0 = std::clock();
      added = RepairClawHoles(s.cloud.holey, s.holes, ClawRepairConfig{}, nullptr, &index).size();
      cpu_ms.push_back(1e3 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
      ms.push_back(Ms(t0));
    }
    std::sort(ms.begin(), ms.end());
    std::sort(cpu_ms.begin(), cpu_ms.end());
    std::printf(
        "[claw] timing %-10s %zu pts, 3 holes: %.1f ms wall median (%.1f-%.1f), %.1f ms "
        "CPU; +%zu pts; index build %.1f ms\n",
        synth::ShapeName(shape).c_str(), s.cloud.holey.size(), ms[4], ms[0], ms[8], cpu_ms[4], added,
        index_ms);
    EXPECT_GT(added, 0u);
  }
}

TEST(ClawHoleRepair, CylinderMiddleGraspHolesFilledOnTheSurface) {
  const Scene s = MakeScene(Shape::kCylinder, GraspWay::kMiddleStraight);
  const auto [added, st] = FillHoles(s, "cylinder middle-straight (local fit)");
  ExpectGoodFill(st);
  // About the hole area times the input density: 3 holes of 25 x 45 mm,
  // less the empty band of D kept along the rims.
  const double density =
      s.cloud.holey.size() / (mesh::SurfaceArea(synth::MakeShape(Shape::kCylinder, s.cloud.size_m)) -
                              3 * 0.025 * 0.045 - M_PI * 0.035 * 0.035 - 2 * M_PI * 0.035 * (0.14 - s.top_z));
  const double expected = density * 3 * 0.025 * 0.045;
  EXPECT_GT(added.size(), 0.7 * expected);
  EXPECT_LT(added.size(), 1.2 * expected);
}

TEST(ClawHoleRepair, CuboidTopGraspHolesOpenIntoTheTopAreFilled) {
  const Scene s = MakeScene(Shape::kCuboid, GraspWay::kTopStraight);
  const auto [added, st] = FillHoles(s, "cuboid top-straight (local fit)");
  ExpectGoodFill(st);
  // Nothing above the boundary's box: the top is the symmetry step's.
  for (const Eigen::Vector3f& p : added) EXPECT_LE(p.z(), s.top_z + 3 * s.d);
}

// A wall's fill bounds the object from the side: its samples deeper than
// 3 mm inside the observed outline at their height are dropped as inside
// the object (the fused pudding and soft boxes' cases are in
// evidence_repair_test). A good fill lies on the outline, curved walls and
// walls leaning towards the top included, and a hole whose boundary runs
// on along the top's rim is still a wall's: none of their samples goes.
// Neither the outline's test nor the widest point's drops a sample that
// is on the wall.
TEST(ClawHoleRepair, AWallsFillOnTheWallLosesNoSampleToTheOutlineTests) {
  ClawRepairConfig untested;
  untested.max_inside_outline_m = 0.0;
  untested.max_outside_widest_m = 0.0;
  for (Shape shape : synth::AllShapes()) {
    Scene s = MakeScene(shape, GraspWay::kTopStraight);
    if (shape == Shape::kCuboid) {
      const Eigen::Vector2f dir = s.patches.dirs[0].cast<float>();
      for (const Eigen::Vector3f& p : s.cloud.holey) {
        if (p.z() > s.top_z - 0.0015 && p.head<2>().dot(dir) > 0.0f) s.holes[0].points_V.push_back(p);
      }
    }
    const std::string name = synth::ShapeName(shape);
    const Fill before = FillHoles(s, name + ", no outline test", untested);
    const Fill after = FillHoles(s, name);
    SCOPED_TRACE(name);
    ExpectGoodFill(after.st);
    EXPECT_EQ(after.added.size(), before.added.size());
  }
}

// A bottom face lies inside its own outline: a hole there (its rim
// horizontal, in the lower half) is not tested, and its fill stays.
TEST(ClawHoleRepair, AHoleInTheBottomKeepsItsFill) {
  Scene s = MakeScene(Shape::kCuboid, GraspWay::kTopStraight);
  float bottom = std::numeric_limits<float>::infinity();
  for (const Eigen::Vector3f& p : s.cloud.holey) bottom = std::min(bottom, p.z());
  constexpr float kRadius = 0.012f;
  PointList cloud;
  HoleBoundary hole;
  hole.kind = HoleKind::kClaw;
  hole.closed = true;
  size_t removed = 0;
  for (const Eigen::Vector3f& p : s.cloud.holey) {
    const float r = p.head<2>().norm();
    if (p.z() < bottom + 1e-4f && r < kRadius) {
      ++removed;
      continue;
    }
    if (p.z() < bottom + 1e-4f && r < kRadius + 0.0015f) hole.points_V.push_back(p);
    cloud.push_back(p);
  }
  ASSERT_GT(removed, 200u);
  const NeighborIndex index(cloud);
  const PointList added = RepairClawHoles(cloud, {hole}, ClawRepairConfig{}, nullptr, &index);
  std::printf("[claw] bottom hole: %zu points removed, %zu added\n", removed, added.size());
  EXPECT_GT(added.size(), removed / 2);
  for (const Eigen::Vector3f& p : added) EXPECT_NEAR(p.z(), bottom, 0.001);
}

TEST(ClawHoleRepair, EveryProtocolShapeAndGraspIsFilled) {
  for (Shape shape : synth::AllShapes()) {
    for (GraspWay grasp : {GraspWay::kTopStraight, GraspWay::kMiddleStraight, GraspWay::kTopOblique}) {
      const Scene s = MakeScene(shape, grasp);
      const std::string label =
          synth::ShapeName(shape) +
          (grasp == GraspWay::kTopStraight ? " top"
                                           : (grasp == GraspWay::kMiddleStraight ? " middle" : " oblique")) +
          " (local fit)";
      const FillStats st = FillHoles(s, label).st;
      SCOPED_TRACE(label);
      ExpectGoodFill(st);
    }
  }
}

// The fallback when no explicit surface explains a hole (in the shape
// zoo's fused clouds: the pudding box's rounded edges, the cereal box's
// ragged rims): a thin-plate spline over the rim's plane. With every
// explicit fit refused (a residual limit none meets) it fills each hole
// alone: on the surface and over the whole hole, on a cylinder, a sphere
// (the bulge over the rim) and the cuboid (its exact flat face still takes
// the plane; the holes at 120 and 240 degrees run over its edges). Not
// asserted: forced onto the holes over the 70 mm rounded box's round edges
// (8 mm radius) it puts 86% of its points within tolerance and covers 70%
// (the surface turns away from the rim's plane past the edge: no graph);
// the explicit fits take those holes.
TEST(ClawHoleRepair, ThinPlateFallbackFillsEveryHoleOnTheSurface) {
  ClawRepairConfig config;
  config.max_fit_sigma_m = 1e-9;  // no curved sheet, quadric or pair of faces passes
  for (Shape shape : {Shape::kCuboid, Shape::kCylinder, Shape::kSphere}) {
    const Scene s = MakeScene(shape, GraspWay::kMiddleStraight);
    const std::string label = synth::ShapeName(shape) + " middle (thin plate)";
    SCOPED_TRACE(label);
    const Fill fill = FillHoles(s, label, config);
    ExpectGoodFill(fill.st);
    EXPECT_LT(fill.st.p95_mm, 1.0);
  }
}

// The paper's Table 2 sizes: on the 5 x 5 x 10 cm cuboid the 2.5 cm claw
// holes at 120 and 240 degrees run over the cuboid's vertical edges.
TEST(ClawHoleRepair, CuboidsOfThePapersSizesAreFilled) {
  for (const Eigen::Vector3d& size : {Eigen::Vector3d(0.05, 0.05, 0.10), Eigen::Vector3d(0.10, 0.10, 0.20)}) {
    for (GraspWay grasp : {GraspWay::kTopStraight, GraspWay::kTopOblique}) {
      const Scene s = MakeScene(Shape::kCuboid, grasp, 50000, size);
      char label[64];
      std::snprintf(label, sizeof(label), "cuboid %.0fx%.0fx%.0f cm %s (local fit)", 100 * size.x(),
                    100 * size.y(), 100 * size.z(), grasp == GraspWay::kTopStraight ? "top" : "oblique");
      const FillStats st = FillHoles(s, label).st;
      SCOPED_TRACE(label);
      ExpectGoodFill(st);
    }
  }
}

TEST(ClawHoleRepair, DeterministicAndIndependentOfTheIndexOwner) {
  const Scene s = MakeScene(Shape::kEllipticCylinder, GraspWay::kTopStraight, 20000);
  const NeighborIndex index(s.cloud.holey);
  const PointList a = RepairClawHoles(s.cloud.holey, s.holes, ClawRepairConfig{}, nullptr, &index);
  const PointList b = RepairClawHoles(s.cloud.holey, s.holes, ClawRepairConfig{});
  ASSERT_FALSE(a.empty());
  EXPECT_TRUE(a == b);
}

TEST(ClawHoleRepair, GivenNormalsAreUsed) {
  // The true outward normals (the TSDF gives them in the pipeline): the
  // paper's Poisson surface is solved from them instead of from estimates,
  // and fills the holes as coarsely as with them (see
  // PaperSettingsFillTheHolesCoarsely).
  const Scene s = MakeScene(Shape::kCylinder, GraspWay::kMiddleStraight, 20000);
  std::vector<Eigen::Vector3f> normals;
  for (const Eigen::Vector3f& p : s.cloud.holey) {
    normals.push_back(p.z() < 1e-4f ? Eigen::Vector3f(0, 0, -1)
                                    : Eigen::Vector3f(p.x(), p.y(), 0).normalized());
  }
  const ClawRepairConfig config = ClawRepairConfig::Paper();
  const auto t0 = std::chrono::steady_clock::now();
  const PointList added = RepairClawHoles(s.cloud.holey, s.holes, config, &normals);
  const double ms = Ms(t0);
  const FillStats st = Evaluate(s, added, 0.005);
  Print("cylinder middle (paper, n, cover@5mm)", s, added, st, ms);
  EXPECT_GE(st.interior_cover, 0.8);
  EXPECT_LT(st.p95_mm, 5.5);
  EXPECT_FALSE(added == RepairClawHoles(s.cloud.holey, s.holes, config));  // estimated: another surface
}

TEST(ClawHoleRepair, AHoleNoExplicitSurfaceExplainsIsLeftOpen) {
  // A "hole" whose rim runs all round the cylinder at mid-height (a
  // boundary round much of the object): its support faces every way, so
  // neither a sheet, a quadric, a pair of faces nor the thin plate takes it.
  const Scene s = MakeScene(Shape::kCylinder, GraspWay::kMiddleStraight, 20000);
  HoleBoundary ring;
  ring.kind = HoleKind::kClaw;
  ring.closed = true;
  const float mid_z = 0.5f * static_cast<float>(s.top_z);
  for (const Eigen::Vector3f& p : s.cloud.holey) {
    if (std::abs(p.z() - mid_z) < 0.001f) {
      ring.points_V.push_back(p);
      ring.source_indices.push_back(-1);
    }
  }
  ASSERT_GT(ring.points_V.size(), 50u);
  std::vector<size_t> left_open(3, 7);  // cleared by the call
  const PointList open =
      RepairClawHoles(s.cloud.holey, {ring}, ClawRepairConfig{}, nullptr, nullptr, &left_open);
  EXPECT_EQ(left_open, std::vector<size_t>{0});
  EXPECT_TRUE(open.empty());
}

TEST(ClawHoleRepair, AHoleWhoseSupportIsMostOfTheCloudIsNoFingersAndLeftOpen) {
  // The rim of the cylinder's whole lower half (a cloud seen half way):
  // the hole's box holds most of the cloud.
  const Scene s = MakeScene(Shape::kCylinder, GraspWay::kMiddleStraight, 20000);
  HoleBoundary rim;
  rim.kind = HoleKind::kClaw;
  rim.closed = true;
  for (const Eigen::Vector3f& p : s.cloud.holey) {
    if (p.z() < 0.002f || (p.x() > 0.0f && p.x() < 0.002f)) {
      rim.points_V.push_back(p);
      rim.source_indices.push_back(-1);
    }
  }
  std::vector<size_t> left_open;
  // After a hole that is not a claw's: the index counts in the list given.
  HoleBoundary top = rim;
  top.kind = HoleKind::kMissingSurface;
  EXPECT_TRUE(
      RepairClawHoles(s.cloud.holey, {top, rim}, ClawRepairConfig{}, nullptr, nullptr, &left_open).empty());
  EXPECT_EQ(left_open, std::vector<size_t>{1});
  // Without the limit it is handed to the fits (and counted open only if
  // none explains it).
  ClawRepairConfig no_limit;
  no_limit.max_support_share = 1.0;
  RepairClawHoles(s.cloud.holey, {rim}, no_limit, nullptr, nullptr, &left_open);
  EXPECT_TRUE(left_open.empty());
  ClawRepairConfig bad;
  bad.max_support_share = 0.0;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
}

TEST(ClawHoleRepair, PaperSettingsFillTheHolesCoarsely) {
  // One Poisson surface of all the side points, depth 6, scale 4.0: cells
  // of ~9 mm on this 14 cm object, so the fill is smooth but a few mm off
  // the faces (rounded towards the edges): it covers the holes within
  // 5 mm, not within 3 D like the local surface. With the top face cut off
  // (the protocol's cut) the surface is open there and sags most near the
  // top: ~85% of the holes' interior within 5 mm, p95 ~5 mm.
  const Scene s = MakeScene(Shape::kCuboid, GraspWay::kMiddleStraight);
  const FillStats st = FillHoles(s, "cuboid middle (paper, cover@5mm)", ClawRepairConfig::Paper(), 0.005).st;
  EXPECT_GE(st.interior_cover, 0.8);
  EXPECT_LT(st.p95_mm, 5.5);
}

}  // namespace
}  // namespace graspfill::repair
