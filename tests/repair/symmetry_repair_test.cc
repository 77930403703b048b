// SPDX-License-Identifier: BSD-3-Clause
// Step 8: the missing top mirrored about the largest cross-section, on the
// paper's protocol clouds in the object frame (= V: z up, the missing top
// at max z), and asymmetric objects that must come back untouched with a
// reason. The missing-surface boundary is built geometrically (the rim just
// below the cut), since steps 1-6 are separate units.
#include "symmetry_repair.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>

#include "claw_hole_repair.hpp"
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

// The missing surface's boundary of a cloud without claw holes: its points
// within 1.5 mm of its top (what steps 2-6 deliver, up to order).
HoleBoundary TopBoundary(const PointList& cloud) {
  float top = -std::numeric_limits<float>::infinity();
  for (const Eigen::Vector3f& p : cloud) top = std::max(top, p.z());
  HoleBoundary b;
  b.kind = HoleKind::kMissingSurface;
  b.closed = true;
  for (const Eigen::Vector3f& p : cloud) {
    if (p.z() >= top - 0.0015f) {
      b.points_V.push_back(p);
      b.source_indices.push_back(-1);
    }
  }
  return b;
}

struct Case {
  PointList cloud;
  PointList claw_fill;    // step 7's points, when filled
  PointList dense_truth;  // ~300k points of the complete surface
  double height{0.0};
  double top_z{0.0};  // the cut
  double d{0.0};
  std::vector<HoleBoundary> claw_holes;  // protocol cases only
  HoleBoundary top;                      // of the cloud before any fill
};

// The protocol's cloud with the top band above (1 - band_fraction) H cut
// off (0: the protocol's own cut, the top face of a flat-topped shape).
Case ProtocolCase(Shape shape, double band_fraction, int num_claw_holes) {
  PaperProtocolConfig config;
  config.shape = shape;
  config.random_pose = false;
  if (band_fraction > 0.0) config.round_top_cut_fraction = band_fraction;
  config.num_claw_holes = num_claw_holes;
  const synth::PaperProtocolCloud pc = synth::MakePaperProtocolCloud(config);
  Case c;
  c.height = pc.size_m.z();
  const double face_cut_z = synth::TopCutZ(config, c.height);
  c.top_z = std::min(face_cut_z, c.height * (1.0 - band_fraction));
  for (const Eigen::Vector3f& p : pc.holey) {
    if (p.z() <= c.top_z) c.cloud.push_back(p);
  }
  c.dense_truth = mesh::SampleSurface(synth::MakeShape(shape, pc.size_m), 300000, 99).points;
  c.d = MeanNn(c.cloud);
  // The completed missing-surface boundary (step 6 closes it across the
  // claw holes' mouths): the true rim just below the cut.
  c.top.kind = HoleKind::kMissingSurface;
  c.top.closed = true;
  for (const Eigen::Vector3f& p : c.dense_truth) {
    if (p.z() <= c.top_z && p.z() > c.top_z - 0.00075) c.top.points_V.push_back(p);
  }
  // The claw holes' rims (top-straight grasp, as paper_protocol.cpp digs
  // them): the cloud points within 1.5 mm outside each finger patch.
  const double zc = face_cut_z - 0.5 * config.claw_hole_height_m + 0.004;
  for (int i = 0; i < num_claw_holes; ++i) {
    const double a = 2.0 * M_PI * i / num_claw_holes;
    const Eigen::Vector2d dir(std::cos(a), std::sin(a));
    HoleBoundary hole;
    for (const Eigen::Vector3f& p : c.cloud) {
      const Eigen::Vector2d xy(p.x(), p.y());
      const double t = dir.x() * xy.y() - dir.y() * xy.x();
      if (xy.dot(dir) > 0.0 && std::abs(t) <= 0.5 * config.claw_hole_width_m + 0.0015 &&
          std::abs(p.z() - zc) <= 0.5 * config.claw_hole_height_m + 0.0015) {
        hole.points_V.push_back(p);
      }
    }
    c.claw_holes.push_back(hole);
  }
  return c;
}

// Step 7 before step 8, as in the pipeline: the claw fills are passed
// along (none of them above the cut: the top is this step's).
Case WithClawHolesFilled(Case c) {
  c.claw_fill = RepairClawHoles(c.cloud, c.claw_holes, ClawRepairConfig{});
  EXPECT_FALSE(c.claw_fill.empty());
  for (const Eigen::Vector3f& p : c.claw_fill) EXPECT_LE(p.z(), c.top_z + 3 * c.d);
  return c;
}

// A closed mesh sampled like the protocol and cut at 92% of its height.
Case MeshCase(const TriangleMesh& mesh, double height) {
  Case c;
  c.height = height;
  c.top_z = 0.92 * height;
  for (const Eigen::Vector3f& p : mesh::SampleSurface(mesh, 50000, 5).points) {
    if (p.z() <= c.top_z) c.cloud.push_back(p);
  }
  c.d = MeanNn(c.cloud);
  c.top = TopBoundary(c.cloud);
  return c;
}

struct MirrorStats {
  double on_surface{0.0};
  double p95_mm{0.0};
  double cover{0.0};  // truth above the cut covered by the repaired cloud
};

MirrorStats Evaluate(const Case& c, const PointList& added) {
  MirrorStats st;
  if (added.empty()) return st;
  const std::vector<double> dist = mesh::NearestDistances(added, c.dense_truth);
  st.on_surface = eval::FractionWithin(dist, kSurfaceTolM);
  st.p95_mm = 1e3 * Percentile(dist, 95.0);
  PointList missing;
  for (const Eigen::Vector3f& p : c.dense_truth) {
    if (p.z() > c.top_z) missing.push_back(p);
  }
  if (missing.empty()) return st;
  PointList repaired = c.cloud;
  repaired.insert(repaired.end(), c.claw_fill.begin(), c.claw_fill.end());
  repaired.insert(repaired.end(), added.begin(), added.end());
  st.cover = eval::FractionWithin(mesh::NearestDistances(missing, repaired), kCoverD * c.d);
  return st;
}

void Print(const char* label, const Case& c, const SymmetryResult& r, const MirrorStats& st, double ms) {
  std::printf(
      "[sym] %-30s %zu pts, H %.0f mm, cut at %.1f mm: plane %.2f mm (H/2 %.2f), "
      "symmetric %d, mismatch %.3f, +%zu pts in %.1f ms; on surface %.3f (p95 %.2f mm), "
      "cover %.3f\n      %s\n",
      label, c.cloud.size(), 1e3 * c.height, 1e3 * c.top_z, 1e3 * r.symmetry_plane_z, 500 * c.height,
      r.symmetric, r.outline_mismatch, r.added_V.size(), ms, st.on_surface, st.p95_mm, st.cover,
      r.reason.c_str());
}

SymmetryResult RunRepair(const Case& c, const SymmetryConfig& config, double* ms) {
  const NeighborIndex index(c.cloud);
  const auto t0 = std::chrono::steady_clock::now();
  SymmetryResult r =
      RepairMissingSurface(c.cloud, c.top, config, &index, c.claw_fill.empty() ? nullptr : &c.claw_fill);
  *ms = Ms(t0);
  return r;
}

TEST(SymmetryRepair, DefaultsValidateAndBadValuesThrow) {
  EXPECT_NO_THROW(SymmetryConfig{}.Validate());
  EXPECT_NO_THROW(SymmetryConfig::Paper().Validate());
  EXPECT_FALSE(SymmetryConfig::Paper().check_symmetry);
  EXPECT_FALSE(SymmetryConfig::Paper().plateau_search);
  SymmetryConfig c;
  c.plateau_tolerance = 1.0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = {};
  c.max_outline_mismatch = -0.1;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = {};
  c.slab_thickness_d = 0.0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  EXPECT_EQ(SymmetryConfig::Paper().fit_sectors, 0);  // the mirror as the paper has it
  c = {};
  c.fit_sectors = -1;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = {};
  c.fit_max_offset_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

TEST(SymmetryRepair, BadInputThrowsAndDegenerateInputAddsNothing) {
  const SymmetryConfig config;
  HoleBoundary ring;
  for (int i = 0; i < 8; ++i) {
    ring.points_V.emplace_back(std::cos(i * 0.8f), std::sin(i * 0.8f), 1.0f);
  }
  SymmetryResult r = RepairMissingSurface({}, ring, config);
  EXPECT_FALSE(r.symmetric);
  EXPECT_TRUE(r.added_V.empty());
  EXPECT_FALSE(r.reason.empty());
  EXPECT_TRUE(std::isnan(r.symmetry_plane_z));
  // A flat patch: the boundary is at the bottom, nothing to mirror.
  PointList flat;
  for (int i = 0; i < 50; ++i) {
    for (int j = 0; j < 50; ++j) flat.emplace_back(0.001f * i, 0.001f * j, 0.0f);
  }
  r = RepairMissingSurface(flat, TopBoundary(flat), config);
  EXPECT_FALSE(r.symmetric);
  EXPECT_TRUE(r.added_V.empty());
  std::printf("[sym] flat patch: %s\n", r.reason.c_str());
  // Too small a boundary.
  HoleBoundary two;
  two.points_V = {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 0, 0)};
  EXPECT_FALSE(RepairMissingSurface(flat, two, config).symmetric);
  PointList bad = flat;
  bad[7].z() = std::numeric_limits<float>::infinity();
  EXPECT_THROW(RepairMissingSurface(bad, ring, config), std::invalid_argument);
  const PointList other = flat;
  const NeighborIndex index(other);
  EXPECT_THROW(RepairMissingSurface(flat, ring, config, &index), std::invalid_argument);
}

// Only the top face cut off (the protocol's cut): the mirror image of the
// bottom is the true top, so every mirrored point lies on the surface.
TEST(SymmetryRepair, CylinderAndCuboidWithTheirTopFaceCutAreClosedExactly) {
  for (Shape shape : {Shape::kCylinder, Shape::kCuboid}) {
    const Case c = ProtocolCase(shape, 0.0, 3);
    double ms = 0.0;
    const SymmetryResult r = RunRepair(c, SymmetryConfig{}, &ms);
    const MirrorStats st = Evaluate(c, r.added_V);
    Print((synth::ShapeName(shape) + ", top face cut").c_str(), c, r, st, ms);
    SCOPED_TRACE(synth::ShapeName(shape));
    ASSERT_TRUE(r.symmetric) << r.reason;
    EXPECT_NEAR(r.symmetry_plane_z, 0.5 * c.height, 1e-3);
    EXPECT_GE(st.on_surface, kSurfaceFraction);
    EXPECT_GE(st.cover, kCoverFraction);
    // The original is kept where the two overlap: nothing within D of it.
    const std::vector<double> to_cloud = mesh::NearestDistances(r.added_V, c.cloud);
    EXPECT_GT(*std::min_element(to_cloud.begin(), to_cloud.end()), 0.5 * c.d);
  }
}

// The boundary test may find only part of a rim (a rounded box held
// obliquely: a third of it). With a constant section the top is still the
// rim's whole outline: the mirror covers all of it, not the part's box.
TEST(SymmetryRepair, APartialRimOfAConstantSectionStillClosesTheWholeTop) {
  Case c = ProtocolCase(Shape::kCuboid, 0.0, 0);
  HoleBoundary part = c.top;
  part.points_V.clear();
  for (const Eigen::Vector3f& p : c.top.points_V) {
    if (p.x() < -0.2f * static_cast<float>(c.height) * 0.5f) part.points_V.push_back(p);  // one side
  }
  ASSERT_GT(part.points_V.size(), 20u);
  ASSERT_LT(part.points_V.size(), c.top.points_V.size() / 2);
  c.top = part;
  double ms = 0.0;
  const SymmetryResult r = RunRepair(c, SymmetryConfig{}, &ms);
  const MirrorStats st = Evaluate(c, r.added_V);
  Print("cuboid, a third of the rim", c, r, st, ms);
  ASSERT_TRUE(r.symmetric) << r.reason;
  EXPECT_GE(st.on_surface, kSurfaceFraction);
  EXPECT_GE(st.cover, kCoverFraction);
}

// The protocol's 8% band cut off a sphere and an ellipsoid, their claw
// holes filled first (step 7, as in the pipeline): the equator is the
// largest cross-section and the mirrored bottom is the true top.
TEST(SymmetryRepair, SphereAndEllipsoidTopsAreMirroredOntoTheSurface) {
  for (Shape shape : {Shape::kSphere, Shape::kEllipsoid}) {
    const Case c = WithClawHolesFilled(ProtocolCase(shape, 0.08, 3));
    double ms = 0.0;
    const SymmetryResult r = RunRepair(c, SymmetryConfig{}, &ms);
    const MirrorStats st = Evaluate(c, r.added_V);
    Print((synth::ShapeName(shape) + ", 8% cut, claws filled").c_str(), c, r, st, ms);
    SCOPED_TRACE(synth::ShapeName(shape));
    ASSERT_TRUE(r.symmetric) << r.reason;
    EXPECT_NEAR(r.symmetry_plane_z, 0.5 * c.height, 0.3e-3);
    EXPECT_GE(st.on_surface, kSurfaceFraction);
    EXPECT_GE(st.cover, kCoverFraction);
  }
}

// Claw fills a little proud of the faces (a fused cloud's are 1-2 mm
// out) widen the sections they reach beyond the plateau tolerance when
// they cover a narrow face: the outline's corners move, so every
// direction (the zoo's 90 x 35 x 110 mm pudding box at seed 15: sizes
// 3-9% up over the claw zone, the plane 35 mm too high). Whether the
// section is constant is asked of what the camera saw: the plane stays
// at mid-height.
TEST(SymmetryRepair, ClawFillsProudOfANarrowFaceDoNotHideAConstantSection) {
  const Eigen::Vector3d size(0.09, 0.035, 0.11);
  const mesh::SurfaceSamples truth = mesh::SampleSurface(synth::MakeShape(Shape::kCuboid, size), 60000, 5);
  Case c;
  c.height = size.z();
  c.top_z = size.z() - 0.0005;
  for (const Eigen::Vector3f& p : truth.points) {
    if (p.z() > c.top_z) continue;  // the top face: missing
    // The upper 40 mm of both narrow faces: the parallel claw's pads,
    // filled 1.5 mm proud and 1.5 mm past the corners.
    if (p.z() > c.height - 0.04 && std::abs(p.x()) > 0.5 * size.x() - 1e-4) {
      c.claw_fill.emplace_back(p.x() + std::copysign(0.0015f, p.x()),
                               p.y() * static_cast<float>((0.5 * size.y() + 0.0015) / (0.5 * size.y())),
                               p.z());
    } else {
      c.cloud.push_back(p);
    }
  }
  c.top = TopBoundary(c.cloud);
  c.dense_truth = truth.points;
  c.d = MeanNn(c.cloud);
  double ms = 0.0;
  const SymmetryResult r = RunRepair(c, SymmetryConfig{}, &ms);
  Print("box, narrow faces' fills proud", c, r, Evaluate(c, r.added_V), ms);
  ASSERT_TRUE(r.symmetric) << r.reason;
  EXPECT_NE(r.reason.find("constant cross-section"), std::string::npos) << r.reason;
  EXPECT_NEAR(r.symmetry_plane_z, 0.5 * c.top_z, 1e-3);
}

// With the claw holes left open their dents bias the plane a little (the
// ellipsoid's holes span more than half of its narrow top sections), but
// it stays within 1 mm and the object symmetric.
TEST(SymmetryRepair, OpenClawHolesMoveThePlaneLittle) {
  for (Shape shape : {Shape::kSphere, Shape::kEllipsoid}) {
    const Case c = ProtocolCase(shape, 0.08, 3);
    double ms = 0.0;
    const SymmetryResult r = RunRepair(c, SymmetryConfig{}, &ms);
    const MirrorStats st = Evaluate(c, r.added_V);
    Print((synth::ShapeName(shape) + ", 8% cut, claws open").c_str(), c, r, st, ms);
    SCOPED_TRACE(synth::ShapeName(shape));
    EXPECT_TRUE(r.symmetric) << r.reason;
    EXPECT_NEAR(r.symmetry_plane_z, 0.5 * c.height, 1e-3);
    EXPECT_LT(st.p95_mm, 2.0);
  }
}

// Claw holes no surface fit explained (passed as open) are the mirror's to
// fill too: the image of the bottom lands in them, on the surface; without
// their boxes they stay open.
TEST(SymmetryRepair, OpenClawHolesAreFilledByTheImage) {
  const Case c = ProtocolCase(Shape::kCuboid, 0.0, 3);
  std::vector<Eigen::AlignedBox3f> open_V;
  PointList in_holes;  // the true surface inside the holes' boxes, under the cut
  for (const HoleBoundary& h : c.claw_holes) {
    ASSERT_GT(h.points_V.size(), 20u);
    Eigen::AlignedBox3f box;
    box.setEmpty();
    for (const Eigen::Vector3f& p : h.points_V) box.extend(p);
    open_V.push_back(box);
    for (const Eigen::Vector3f& p : c.dense_truth) {
      if (box.contains(p) && p.z() <= c.top_z - 3 * c.d) in_holes.push_back(p);
    }
  }
  ASSERT_GT(in_holes.size(), 1000u);
  const NeighborIndex index(c.cloud);
  const auto hole_cover = [&](const SymmetryResult& r) {
    PointList repaired = c.cloud;
    repaired.insert(repaired.end(), r.added_V.begin(), r.added_V.end());
    return eval::FractionWithin(mesh::NearestDistances(in_holes, repaired), kCoverD * c.d);
  };
  const SymmetryResult closed_top = RepairMissingSurface(c.cloud, c.top, SymmetryConfig{}, &index);
  const SymmetryResult filled =
      RepairMissingSurface(c.cloud, c.top, SymmetryConfig{}, &index, nullptr, &open_V);
  ASSERT_TRUE(filled.symmetric) << filled.reason;
  std::printf(
      "[sym] cuboid, 3 claw holes open: covered %.3f by the top's image alone, %.3f with the "
      "holes' boxes (+%zu pts)\n      %s\n",
      hole_cover(closed_top), hole_cover(filled), filled.added_V.size() - closed_top.added_V.size(),
      filled.reason.c_str());
  EXPECT_LT(hole_cover(closed_top), 0.5);
  EXPECT_GE(hole_cover(filled), kCoverFraction);
  EXPECT_NE(filled.reason.find("claw hole"), std::string::npos);
  const MirrorStats st = Evaluate(c, filled.added_V);
  EXPECT_GE(st.on_surface, kSurfaceFraction);
  // An empty box changes nothing.
  const std::vector<Eigen::AlignedBox3f> empty_box(1, Eigen::AlignedBox3f());
  EXPECT_EQ(RepairMissingSurface(c.cloud, c.top, SymmetryConfig{}, &index, nullptr, &empty_box).added_V,
            closed_top.added_V);
}

// The protocol's 8% band cut off a cylinder. The band's height cannot be
// observed on a constant cross-section, so the plane is the middle of the
// observed height (H/2 - cut/2, within "a few mm" of H/2: 5.6 mm here) and
// the mirrored bottom closes the cylinder at the cut. The paper's search
// from the median (which the bottom disc pulls down) lands much lower.
TEST(SymmetryRepair, CylinderWithTheProtocolBandCutIsClosedAtTheCut) {
  const Case c = ProtocolCase(Shape::kCylinder, 0.08, 3);
  double ms = 0.0;
  const SymmetryResult r = RunRepair(c, SymmetryConfig{}, &ms);
  const MirrorStats st = Evaluate(c, r.added_V);
  Print("cylinder, 8% cut", c, r, st, ms);
  ASSERT_TRUE(r.symmetric) << r.reason;
  const double band = c.height - c.top_z;
  EXPECT_NEAR(r.symmetry_plane_z, 0.5 * c.top_z, 1e-3);
  EXPECT_NEAR(r.symmetry_plane_z, 0.5 * c.height, 0.5 * band + 1e-3);
  // Every mirrored point is on the cylinder closed at the cut: on the side
  // (r = 35 mm) or on a disc at the cut's height.
  int on_closure = 0;
  for (const Eigen::Vector3f& p : r.added_V) {
    const double radial = std::hypot(p.x(), p.y());
    on_closure += std::abs(radial - 0.035) < 1e-3 || (std::abs(p.z() - c.top_z) < 1e-3 && radial < 0.036);
  }
  EXPECT_GE(on_closure, kSurfaceFraction * r.added_V.size());
  // The top is closed: the disc covers the cut's whole cross-section.
  EXPECT_GT(r.added_V.size(), 0.8 * M_PI * 0.035 * 0.035 / (4 * c.d * c.d));
  PointList repaired = c.cloud;
  repaired.insert(repaired.end(), r.added_V.begin(), r.added_V.end());
  const eval::CloudMetrics before = eval::Compare(c.cloud, c.dense_truth);
  const eval::CloudMetrics after = eval::Compare(repaired, c.dense_truth);
  std::printf("[sym] cylinder 8%% cut, vs the complete truth: chamfer %.2f -> %.2f mm^2\n",
              before.chamfer_mm2, after.chamfer_mm2);
  EXPECT_LT(after.chamfer_mm2, before.chamfer_mm2);

  const SymmetryResult paper = RunRepair(c, SymmetryConfig::Paper(), &ms);
  std::printf("[sym] paper's search from the median: plane %.2f mm\n", 1e3 * paper.symmetry_plane_z);
  EXPECT_GT(std::abs(paper.symmetry_plane_z - 0.5 * c.height), std::abs(r.symmetry_plane_z - 0.5 * c.height));
}

TEST(SymmetryRepair, EveryProtocolShapeIsFoundSymmetric) {
  for (Shape shape : synth::AllShapes()) {
    const Case c = ProtocolCase(shape, 0.08, 3);
    double ms = 0.0;
    const SymmetryResult r = RunRepair(c, SymmetryConfig{}, &ms);
    const MirrorStats st = Evaluate(c, r.added_V);
    Print(synth::ShapeName(shape).c_str(), c, r, st, ms);
    SCOPED_TRACE(synth::ShapeName(shape));
    EXPECT_TRUE(r.symmetric) << r.reason;
    EXPECT_FALSE(r.added_V.empty());
    // Within half the unobservable band (+1 mm) of the true plane.
    EXPECT_NEAR(r.symmetry_plane_z, 0.5 * c.height, 0.5 * (c.height - c.top_z) + 1e-3);
  }
}

// --- Asymmetric objects: nothing added, and why. ---

void AddQuad(TriangleMesh* m, const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
             const Eigen::Vector3f& d) {
  const int i = static_cast<int>(m->vertices.size());
  m->vertices.insert(m->vertices.end(), {a, b, c, d});
  m->triangles.emplace_back(i, i + 1, i + 2);
  m->triangles.emplace_back(i, i + 2, i + 3);
}

// An axis-aligned box [lo, hi] rotated by `yaw` about z (triangle soup;
// orientation is irrelevant to the sampler).
TriangleMesh Box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, float yaw = 0.0f) {
  const Eigen::Matrix3f r = Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  Eigen::Vector3f v[8];
  for (int k = 0; k < 8; ++k) {
    v[k] = r * Eigen::Vector3f(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
  }
  TriangleMesh m;
  AddQuad(&m, v[0], v[1], v[3], v[2]);  // bottom
  AddQuad(&m, v[4], v[5], v[7], v[6]);  // top
  AddQuad(&m, v[0], v[1], v[5], v[4]);
  AddQuad(&m, v[2], v[3], v[7], v[6]);
  AddQuad(&m, v[0], v[2], v[6], v[4]);
  AddQuad(&m, v[1], v[3], v[7], v[5]);
  return m;
}

// A closed frustum: radius r0 at z = 0, r1 at z = h.
TriangleMesh Frustum(float r0, float r1, float h, int segments = 128) {
  TriangleMesh m;
  for (int i = 0; i < segments; ++i) {
    const float a0 = 2.0f * static_cast<float>(M_PI) * i / segments;
    const float a1 = 2.0f * static_cast<float>(M_PI) * (i + 1) / segments;
    const Eigen::Vector3f b0(r0 * std::cos(a0), r0 * std::sin(a0), 0),
        b1(r0 * std::cos(a1), r0 * std::sin(a1), 0);
    const Eigen::Vector3f t0(r1 * std::cos(a0), r1 * std::sin(a0), h),
        t1(r1 * std::cos(a1), r1 * std::sin(a1), h);
    AddQuad(&m, b0, b1, t1, t0);
    const int c = static_cast<int>(m.vertices.size());
    m.vertices.insert(m.vertices.end(), {Eigen::Vector3f(0, 0, 0), b1, b0, Eigen::Vector3f(0, 0, h), t0, t1});
    m.triangles.emplace_back(c, c + 1, c + 2);
    m.triangles.emplace_back(c + 3, c + 4, c + 5);
  }
  return m;
}

void ExpectRejected(const char* label, const Case& c, const char* why) {
  double ms = 0.0;
  const SymmetryResult r = RunRepair(c, SymmetryConfig{}, &ms);
  Print(label, c, r, MirrorStats{}, ms);
  EXPECT_FALSE(r.symmetric) << label;
  EXPECT_TRUE(r.added_V.empty()) << label;
  EXPECT_NE(r.reason.find(why), std::string::npos) << label << ": " << r.reason;
  // The paper's method, without the checks, would have mirrored something.
  const SymmetryResult paper = RunRepair(c, SymmetryConfig::Paper(), &ms);
  std::printf("[sym]   the paper's method would add %zu points (plane %.1f mm)\n", paper.added_V.size(),
              1e3 * paper.symmetry_plane_z);
}

TEST(SymmetryRepair, FrustumIsNotMirrored) {
  // Wide at the bottom: the largest section is the base, and the observed
  // part above it is far longer than the part below.
  ExpectRejected("frustum r 40 -> 20 mm", MeshCase(Frustum(0.04f, 0.02f, 0.14f), 0.14),
                 "no horizontal symmetry plane");
}

TEST(SymmetryRepair, CuboidWithABumpHighUpIsNotMirrored) {
  // A 3 cm bump across the +x face between 9 and 12 cm: the largest
  // section is the bump, and mirroring about it would add 8 cm of object
  // above the cut.
  TriangleMesh m = Box({-0.035f, -0.035f, 0.0f}, {0.035f, 0.035f, 0.14f});
  m.Append(Box({0.035f, -0.035f, 0.09f}, {0.065f, 0.035f, 0.12f}));
  ExpectRejected("cuboid with a high bump", MeshCase(m, 0.14), "would add");
}

TEST(SymmetryRepair, TwistedBoxIsNotMirrored) {
  // Two 7 x 7 cm boxes stacked, the upper turned by 45 degrees: every
  // section has the same area, but the outlines above the plane do not
  // match those below.
  TriangleMesh m = Box({-0.035f, -0.035f, 0.0f}, {0.035f, 0.035f, 0.07f});
  m.Append(Box({-0.035f, -0.035f, 0.07f}, {0.035f, 0.035f, 0.14f}, static_cast<float>(M_PI / 4)));
  ExpectRejected("twisted box", MeshCase(m, 0.14), "differs from its mirror image");
}

// A fruit that leans: a 60 mm ball whose upper half is sheared towards +x
// (x += 0.1 (z - 30 mm)), cut at 92% of its height, with a claw hole on
// its +x side (10-20 mm above the centre, 50 degrees wide). The image of
// the lower half lies 1-2 mm inside the hole's wall; moved onto the walls
// seen around the hole, it fills the hole on the surface. On the ball
// itself (no lean) the fit moves the image by the sampling noise only.
TEST(SymmetryRepair, TheImageOfALeaningFruitIsMovedOntoTheWallsAroundIt) {
  constexpr double kLean = 0.1, kR = 0.03;
  for (const bool lean : {true, false}) {
    TriangleMesh mesh = synth::MakeShape(Shape::kSphere, Eigen::Vector3d::Constant(2 * kR));
    for (Eigen::Vector3f& v : mesh.vertices) {
      if (lean && v.z() > kR) v.x() += static_cast<float>(kLean * (v.z() - kR));
    }
    Case c = MeshCase(mesh, 2 * kR);
    c.dense_truth = mesh::SampleSurface(mesh, 300000, 99).points;
    const auto in_hole = [&](const Eigen::Vector3f& p) {
      return p.z() > kR + 0.010 && p.z() < kR + 0.020 && p.x() > 0.0f &&
             std::abs(std::atan2(p.y(), p.x())) < 25.0 * M_PI / 180.0;
    };
    c.cloud.erase(std::remove_if(c.cloud.begin(), c.cloud.end(), in_hole), c.cloud.end());
    Eigen::AlignedBox3f hole;
    hole.setEmpty();
    PointList hole_truth;
    for (const Eigen::Vector3f& p : c.dense_truth) {
      if (in_hole(p)) hole.extend(p), hole_truth.push_back(p);
    }
    const std::vector<Eigen::AlignedBox3f> open_V(1, hole);
    const NeighborIndex index(c.cloud);
    SymmetryConfig as_is;
    as_is.fit_sectors = 0;
    const SymmetryResult mirrored = RepairMissingSurface(c.cloud, c.top, as_is, &index, nullptr, &open_V);
    const SymmetryResult fitted =
        RepairMissingSurface(c.cloud, c.top, SymmetryConfig{}, &index, nullptr, &open_V);
    SCOPED_TRACE(lean ? "leaning" : "upright");
    ASSERT_TRUE(mirrored.symmetric) << mirrored.reason;
    ASSERT_TRUE(fitted.symmetric) << fitted.reason;
    ASSERT_EQ(fitted.added_V.size(), mirrored.added_V.size());
    const MirrorStats st_mirrored = Evaluate(c, mirrored.added_V), st_fitted = Evaluate(c, fitted.added_V);
    // The hole's truth covered within 1 mm, by either.
    const auto hole_cover = [&](const SymmetryResult& r) {
      return eval::FractionWithin(mesh::NearestDistances(hole_truth, r.added_V), 1e-3);
    };
    double moved_mm = 0.0;
    for (size_t i = 0; i < fitted.added_V.size(); ++i) {
      moved_mm =
          std::max(moved_mm, 1e3 * static_cast<double>((fitted.added_V[i] - mirrored.added_V[i]).norm()));
    }
    std::printf(
        "[sym] ball of 60 mm, %s, claw hole on the side: the image as is p95 %.2f mm, hole "
        "covered %.3f; fitted p95 %.2f mm, covered %.3f (points moved up to %.2f mm)\n",
        lean ? "upper half leaning" : "upright", st_mirrored.p95_mm, hole_cover(mirrored), st_fitted.p95_mm,
        hole_cover(fitted), moved_mm);
    if (lean) {
      // The hole; the top (cut at 92%) is steeper than 45 degrees, where
      // the image is not moved, so it keeps the lean's error there.
      EXPECT_LT(hole_cover(mirrored), 0.5);
      EXPECT_GE(hole_cover(fitted), 0.95);
      EXPECT_LT(st_fitted.p95_mm, st_mirrored.p95_mm);
    } else {
      EXPECT_LT(moved_mm, 0.25);
      EXPECT_LT(st_fitted.p95_mm, 1.0);
    }
  }
}

TEST(SymmetryRepair, TimingOnA50kCloud) {
  PaperProtocolConfig config;
  config.shape = Shape::kCylinder;
  config.random_pose = false;
  config.num_points = 66000;  // ~50k after the cuts
  const synth::PaperProtocolCloud pc = synth::MakePaperProtocolCloud(config);
  const HoleBoundary boundary = TopBoundary(pc.holey);
  const NeighborIndex index(pc.holey);
  std::vector<double> ms, cpu_ms;
  SymmetryResult r;
  for (int run = 0; run < 9; ++run) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    r = RepairMissingSurface(pc.holey, boundary, SymmetryConfig{}, &index);
    cpu_ms.push_back(1e3 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
    ms.push_back(Ms(t0));
  }
  std::sort(ms.begin(), ms.end());
  std::sort(cpu_ms.begin(), cpu_ms.end());
  std::printf(
      "[sym] timing cylinder %zu pts: %.1f ms wall median (%.1f-%.1f), %.1f ms CPU; "
      "+%zu pts\n",
      pc.holey.size(), ms[4], ms[0], ms[8], cpu_ms[4], r.added_V.size());
  EXPECT_TRUE(r.symmetric);
}

}  // namespace
}  // namespace graspfill::repair
