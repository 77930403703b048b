// SPDX-License-Identifier: BSD-3-Clause
#include "boundary_linking.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "boundary_detection.hpp"
#include "boundary_fixtures.hpp"
#include "cpu_time.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "neighbor_index.hpp"
#include "synth/paper_protocol.hpp"
#include "synth/shapes.hpp"

namespace graspfill::repair {
namespace {

using testing::BestOf3CpuMs;
using testing::Disc;
using testing::PlaneWithHoles;

// Detection then linking, with the detector's info unless `use_info` is
// false (the paper's Eq. 3 alone).
std::vector<BoundaryLine> DetectAndLink(const PointList& points, bool use_info = true,
                                        const LinkConfig& link = LinkConfig{}) {
  const NeighborIndex index(points);
  std::vector<BoundaryPointInfo> info;
  const std::vector<int> boundary = DetectBoundaryPoints(index, BoundaryConfig{}, nullptr, &info);
  return LinkBoundaryPoints(points, boundary, link, use_info ? &info : nullptr);
}

// Distances of a line's points to the circle of `disc`.
struct CircleFit {
  float max_m{0.0f};
  float rms_m{0.0f};
};
CircleFit DistanceToCircle(const PointList& points, const BoundaryLine& line, const Disc& disc) {
  CircleFit fit;
  double sum_sq = 0.0;
  for (const int i : line.indices) {
    const Eigen::Vector2f rel = points[static_cast<size_t>(i)].head<2>() - disc.centre;
    const float d = std::abs(rel.norm() - disc.radius_m);
    fit.max_m = std::max(fit.max_m, d);
    sum_sq += static_cast<double>(d) * d;
  }
  fit.rms_m = static_cast<float>(std::sqrt(sum_sq / static_cast<double>(line.indices.size())));
  return fit;
}

// True when the line goes once around `disc` (walking it, the angle seen
// from the centre turns by 2*pi) with no link longer than `max_link_m`.
bool GoesAround(const PointList& points, const BoundaryLine& line, const Disc& disc, float max_link_m) {
  double winding = 0.0;
  float longest = 0.0f;
  for (size_t k = 0; k < line.indices.size(); ++k) {
    const Eigen::Vector2f a = points[static_cast<size_t>(line.indices[k])].head<2>() - disc.centre;
    const Eigen::Vector2f b =
        points[static_cast<size_t>(line.indices[(k + 1) % line.indices.size()])].head<2>() - disc.centre;
    winding += std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
    longest = std::max(longest, (a - b).norm());
  }
  return longest <= max_link_m && std::abs(std::abs(winding) - 2 * M_PI) < 0.1;
}

// No link may be longer than a bridge over a gap: 2 x the reach of 3 local
// spacings, the local spacing being ~1.0-1.1 of sqrt(A / N) on these planes.
constexpr float kMaxLink = 7.0f;

TEST(LinkConfig, DefaultsAndValidate) {
  const LinkConfig config;
  EXPECT_EQ(config.candidates, 6);
  EXPECT_DOUBLE_EQ(config.max_link_factor, 3.0);
  EXPECT_EQ(config.min_points, 10);
  EXPECT_NEAR(config.max_deflection_rad, 3 * M_PI / 4, 1e-12);
  EXPECT_DOUBLE_EQ(config.absorb_factor, 1.5);
  EXPECT_NO_THROW(config.Validate());
  LinkConfig bad;
  bad.candidates = 0;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  bad = LinkConfig{};
  bad.min_points = 2;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  bad = LinkConfig{};
  bad.absorb_factor = bad.max_link_factor;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  bad = LinkConfig{};
  bad.max_deflection_rad = 4.0;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
}

TEST(LinkBoundaryPoints, BadInput) {
  const PointList points(20, Eigen::Vector3f::Zero());
  EXPECT_THROW(LinkBoundaryPoints(points, {0, 20}, LinkConfig{}), std::invalid_argument);
  EXPECT_THROW(LinkBoundaryPoints(points, {-1}, LinkConfig{}), std::invalid_argument);
  EXPECT_TRUE(LinkBoundaryPoints(points, {}, LinkConfig{}).empty());
  // All coincident: no spacing, no line (and no crash).
  std::vector<int> all(20);
  for (int i = 0; i < 20; ++i) all[static_cast<size_t>(i)] = i;
  EXPECT_TRUE(LinkBoundaryPoints(points, all, LinkConfig{}).empty());
  // Info of the wrong size.
  const std::vector<BoundaryPointInfo> info(3);
  EXPECT_THROW(LinkBoundaryPoints(points, all, LinkConfig{}, &info), std::invalid_argument);
}

TEST(LinkBoundaryPoints, OrderedCircleBecomesOneRing) {
  // Points of a circle given in shuffled order, plus duplicates of indices.
  PointList points;
  const int n = 100;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * ((i * 37) % n) / n;
    points.emplace_back(0.01f * static_cast<float>(std::cos(a)), 0.01f * static_cast<float>(std::sin(a)),
                        0.0f);
  }
  std::vector<int> ids;
  for (int i = 0; i < n; ++i) ids.push_back(i);
  ids.push_back(5);
  const std::vector<BoundaryLine> lines = LinkBoundaryPoints(points, ids, LinkConfig{});
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_TRUE(lines[0].closed);
  // Every point in order around the circle, none absorbed (they are 0.63
  // mm apart and the spacing is 0.63 mm: absorption takes < 1.5 of them).
  EXPECT_GE(lines[0].indices.size(), static_cast<size_t>(n / 2));
  EXPECT_TRUE(GoesAround(points, lines[0], Disc{Eigen::Vector2f::Zero(), 0.01f}, 0.002f));
}

class PlaneHole : public ::testing::TestWithParam<bool> {};

// With the detector's info and without it (the paper's Eq. 3 alone).
TEST_P(PlaneHole, GivesOneRingAndTheOuterEdge) {
  // 10 x 10 cm, 20k points: spacing s = sqrt(A / N) = 0.71 mm.
  const float half = 0.05f;
  const int n = 20000;
  const float spacing = std::sqrt(4 * half * half / n);
  const Disc hole{Eigen::Vector2f(0.005f, -0.004f), 0.015f};
  const PointList points = PlaneWithHoles(n, half, {hole}, 11);
  const std::vector<BoundaryLine> lines = DetectAndLink(points, GetParam());
  int rings = 0, outer = 0;
  for (const BoundaryLine& line : lines) {
    EXPECT_TRUE(line.closed);
    EXPECT_GE(line.indices.size(), 10u);
    const CircleFit fit = DistanceToCircle(points, line, hole);
    if (fit.rms_m < 2 * spacing) {
      // The hole's ring: on the rim (the flagged band is up to ~3 spacings
      // deep where the random sample leaves a bay), once around it.
      ++rings;
      EXPECT_LT(fit.max_m, 3.5f * spacing);
      EXPECT_LT(fit.rms_m, 1.5f * spacing);
      EXPECT_TRUE(GoesAround(points, line, hole, kMaxLink * spacing));
      std::printf("hole ring: %zu points, %.2f spacings rms (%.2f max) off the circle\n", line.indices.size(),
                  fit.rms_m / spacing, fit.max_m / spacing);
    } else {
      // The square's outer edge is a boundary too; the criterion cannot
      // tell it from a hole. It is linked into one more closed ring (its
      // 90 degree corners included) that hugs the edge.
      ++outer;
      for (const int i : line.indices) {
        const Eigen::Vector3f& p = points[static_cast<size_t>(i)];
        EXPECT_LT(half - std::max(std::abs(p.x()), std::abs(p.y())), 3.5f * spacing);
      }
      std::printf("outer-edge line: %zu points\n", line.indices.size());
    }
  }
  EXPECT_EQ(rings, 1);
  EXPECT_EQ(outer, 1);
}

INSTANTIATE_TEST_SUITE_P(LinkBoundaryPoints, PlaneHole, ::testing::Bool());

TEST(LinkBoundaryPoints, TwoNearbyHolesStayTwoLines) {
  const float half = 0.05f;
  const int n = 20000;
  const float spacing = std::sqrt(4 * half * half / n);
  // Radius 8 mm each, rims 3 spacings (2.1 mm) apart.
  const float r = 0.008f;
  const float gap = 3 * spacing;
  const Disc a{Eigen::Vector2f(-(r + 0.5f * gap), 0.0f), r};
  const Disc b{Eigen::Vector2f(r + 0.5f * gap, 0.0f), r};
  for (const uint64_t seed : {21u, 22u, 23u}) {
    const PointList points = PlaneWithHoles(n, half, {a, b}, seed);
    const std::vector<BoundaryLine> lines = DetectAndLink(points);
    int ring_a = 0, ring_b = 0;
    for (const BoundaryLine& line : lines) {
      const CircleFit fa = DistanceToCircle(points, line, a);
      const CircleFit fb = DistanceToCircle(points, line, b);
      if (fa.rms_m < 2 * spacing || fb.rms_m < 2 * spacing) {
        // One hole's ring, with no point taken from the other hole.
        const bool is_a = fa.rms_m < fb.rms_m;
        ++(is_a ? ring_a : ring_b);
        EXPECT_LT((is_a ? fa : fb).max_m, 3.5f * spacing) << "seed " << seed;
        EXPECT_TRUE(GoesAround(points, line, is_a ? a : b, kMaxLink * spacing)) << "seed " << seed;
      } else {
        // Not a mixture of the two holes: only the outer edge is left.
        for (const int i : line.indices) {
          const Eigen::Vector3f& p = points[static_cast<size_t>(i)];
          EXPECT_LT(half - std::max(std::abs(p.x()), std::abs(p.y())), 3.5f * spacing) << "seed " << seed;
        }
      }
    }
    EXPECT_EQ(ring_a, 1) << "seed " << seed;
    EXPECT_EQ(ring_b, 1) << "seed " << seed;
  }
}

TEST(LinkBoundaryPoints, ClosedSurfacesGiveNoLines) {
  for (const synth::Shape shape : {synth::Shape::kSphere, synth::Shape::kCylinder}) {
    const TriangleMesh mesh = synth::MakeShape(shape, synth::DefaultSize(shape));
    const PointList points = mesh::SampleSurface(mesh, 30000, 3).points;
    EXPECT_TRUE(DetectAndLink(points).empty()) << synth::ShapeName(shape);
  }
}

TEST(LinkBoundaryPoints, PaperCylinderLinesFollowTheRims) {
  synth::PaperProtocolConfig config;
  config.shape = synth::Shape::kCylinder;
  config.random_pose = false;
  const synth::PaperProtocolCloud cloud = synth::MakePaperProtocolCloud(config);
  const double height = cloud.size_m.z();
  const double area = M_PI * cloud.size_m.x() * height + 0.5 * M_PI * std::pow(cloud.size_m.x(), 2);
  const double spacing = std::sqrt(area / config.num_points);
  const testing::ProtocolHoles holes = testing::HolesOf(config, cloud.size_m);
  const std::vector<BoundaryLine> lines = DetectAndLink(cloud.holey);
  ASSERT_FALSE(lines.empty());
  // Every linked point lies on a rim; the top rim is covered all round
  // (apart from where the claw holes cut into it) and each claw hole's rim
  // is visited (its bottom edge, the farthest from the top).
  const double top_z = synth::TopCutZ(config, height);
  std::vector<int> top_sectors(36, 0);
  std::vector<int> hole_bottom_hits(3, 0);
  size_t total = 0;
  for (const BoundaryLine& line : lines) {
    EXPECT_TRUE(line.closed);
    total += line.indices.size();
    for (const int i : line.indices) {
      const Eigen::Vector3f& p = cloud.holey[static_cast<size_t>(i)];
      int hole = -1;
      const double d = testing::RimDistance(p, holes, &hole);
      EXPECT_LT(d, 3.5 * spacing) << "(" << p.transpose() << ")";
      if (hole < 0) {
        const double a = std::atan2(p.y(), p.x()) + M_PI;
        ++top_sectors[static_cast<size_t>(std::min(35, static_cast<int>(a / (2 * M_PI) * 36)))];
      } else if (p.z() < top_z - config.claw_hole_height_m + 0.004 + 3 * spacing) {
        ++hole_bottom_hits[static_cast<size_t>(hole)];
      }
    }
  }
  std::printf("paper cylinder: %zu closed lines, %zu points\n", lines.size(), total);
  // Sectors whose top rim is all inside a claw hole (27 mm wide of 220 mm
  // around: ~4.4 sectors each) may be empty; the other ~22 may not.
  int covered = 0;
  for (const int hits : top_sectors) covered += hits > 0;
  EXPECT_GE(covered, 36 - 3 * 5);
  for (int h = 0; h < 3; ++h) EXPECT_GT(hole_bottom_hits[static_cast<size_t>(h)], 10) << h;
}

// Every paper shape, in a random pose: one closed line (the missing top's
// rim, in and out of the three claw holes), nothing else: in particular the
// triangular prism's vertical edges, which the detector flags below the cut
// as well, are cut off. Every linked point lies in the band from the claw
// holes' bottom to the cut (object frame).
TEST(LinkBoundaryPoints, EveryPaperShapeGivesOneClosedLine) {
  for (const synth::Shape shape : synth::AllShapes()) {
    synth::PaperProtocolConfig config;
    config.shape = shape;
    const synth::PaperProtocolCloud cloud = synth::MakePaperProtocolCloud(config);
    const std::vector<BoundaryLine> lines = DetectAndLink(cloud.holey);
    ASSERT_EQ(lines.size(), 1u) << synth::ShapeName(shape);
    EXPECT_TRUE(lines[0].closed);
    const double top_z = synth::TopCutZ(config, cloud.size_m.z());
    const double hole_bottom_z = top_z - config.claw_hole_height_m + 0.004;
    const Eigen::Isometry3f T_object_cloud = cloud.T_cloud_object.inverse().cast<float>();
    float z_min = 1e9f, z_max = -1e9f;
    for (const int i : lines[0].indices) {
      const float z = (T_object_cloud * cloud.holey[static_cast<size_t>(i)]).z();
      z_min = std::min(z_min, z);
      z_max = std::max(z_max, z);
    }
    std::printf("%s: %zu points, z %.1f..%.1f mm (claw holes' bottom %.1f, cut %.1f)\n",
                synth::ShapeName(shape).c_str(), lines[0].indices.size(), z_min * 1e3, z_max * 1e3,
                hole_bottom_z * 1e3, top_z * 1e3);
    // 3 mm: ~3 spacings of these 50k-point samples.
    EXPECT_GT(z_min, hole_bottom_z - 0.003) << synth::ShapeName(shape);
    EXPECT_LT(z_max, top_z + 0.001) << synth::ShapeName(shape);
    EXPECT_LT(z_min, hole_bottom_z + 0.003) << synth::ShapeName(shape);  // reaches the holes
  }
}

// Timing on ~50k points (printed, not asserted).
TEST(LinkBoundaryPoints, TimingOn50k) {
  synth::PaperProtocolConfig config;
  config.shape = synth::Shape::kCylinder;
  config.num_points = 66000;  // ~50k left after the cut and the holes
  const synth::PaperProtocolCloud cloud = synth::MakePaperProtocolCloud(config);
  const NeighborIndex index(cloud.holey);
  std::vector<BoundaryPointInfo> info;
  const std::vector<int> boundary = DetectBoundaryPoints(index, BoundaryConfig{}, nullptr, &info);
  std::vector<BoundaryLine> lines;
  const double best =
      BestOf3CpuMs([&] { lines = LinkBoundaryPoints(cloud.holey, boundary, LinkConfig{}, &info); });
  size_t linked = 0;
  for (const BoundaryLine& line : lines) linked += line.indices.size();
  std::printf(
      "linking, %zu points, %zu boundary points: %.2f ms (best of 3, CPU), %zu lines, "
      "%zu points linked\n",
      cloud.holey.size(), boundary.size(), best, lines.size(), linked);
  EXPECT_FALSE(lines.empty());
}

}  // namespace
}  // namespace graspfill::repair
