// SPDX-License-Identifier: BSD-3-Clause
// The chained repair: contract tests (input kept, provenance, bad input,
// no-op cases). Accuracy against the paper's tables is `graspfill bench
// repair`'s job.
#include "graspfill/repair/repairer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "graspfill/mesh/mesh_geometry.hpp"
#include "repair_steps.hpp"
#include "synth/paper_protocol.hpp"
#include "synth/shapes.hpp"

namespace graspfill::repair {
namespace {

ObjectCloud Cloud(const std::vector<Eigen::Vector3f>& points) {
  ObjectCloud c;
  c.points_G = points;
  return c;
}

TEST(Repairer, KeepsEveryInputPointAndLabelsTheAddedOnes) {
  synth::PaperProtocolConfig pc;
  pc.shape = synth::Shape::kCylinder;
  pc.num_points = 20000;
  const synth::PaperProtocolCloud c = synth::MakePaperProtocolCloud(pc);
  const RepairResult r = Repair(Cloud(c.holey));
  ASSERT_GE(r.cloud.size(), c.holey.size());
  ASSERT_EQ(r.cloud.provenance.size(), r.cloud.size());
  for (size_t i = 0; i < c.holey.size(); ++i) {
    ASSERT_EQ(r.cloud.points_G[i], c.holey[i]) << i;
    ASSERT_EQ(r.cloud.provenance[i], Provenance::kObserved);
  }
  int surface = 0, symmetry = 0;
  for (size_t i = c.holey.size(); i < r.cloud.size(); ++i) {
    ASSERT_NE(r.cloud.provenance[i], Provenance::kObserved);
    surface += r.cloud.provenance[i] == Provenance::kSurface;
    symmetry += r.cloud.provenance[i] == Provenance::kSymmetry;
  }
  int reported = 0;
  for (const HoleSummary& h : r.report.holes) reported += h.points_added;
  EXPECT_EQ(reported, surface + symmetry);
  EXPECT_FALSE(r.report.timings.empty());
}

// The returned cloud carries the repair's holes, so an embedder who
// publishes it sends what the CLI sends; holes the input carried from an
// earlier repair are not passed on as this one's.
TEST(Repairer, TheCloudCarriesTheHolesItsReportLists) {
  synth::PaperProtocolConfig pc;
  pc.shape = synth::Shape::kCylinder;
  pc.num_points = 20000;
  const synth::PaperProtocolCloud c = synth::MakePaperProtocolCloud(pc);
  ObjectCloud input = Cloud(c.holey);
  HoleSummary stale;
  stale.points_added = 12345;
  input.holes = {stale, stale};
  const RepairResult r = Repair(input);
  ASSERT_EQ(r.report.status, RepairStatus::kRepaired);
  ASSERT_FALSE(r.report.holes.empty());
  ASSERT_EQ(r.cloud.holes.size(), r.report.holes.size());
  for (size_t k = 0; k < r.cloud.holes.size(); ++k) {
    EXPECT_EQ(r.cloud.holes[k].kind, r.report.holes[k].kind) << k;
    EXPECT_EQ(r.cloud.holes[k].points_added, r.report.holes[k].points_added) << k;
    EXPECT_EQ(r.cloud.holes[k].box_min_G, r.report.holes[k].box_min_G) << k;
  }
  // Unchanged (too few points): no holes of this repair, none of the input's.
  ObjectCloud few = Cloud({Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(0.01f, 0, 0)});
  few.holes = {stale};
  EXPECT_TRUE(Repair(few).cloud.holes.empty());
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
}

// The protocol's ellipsoid with 2% of its height cut off, held at the top:
// the three finger holes notch its 11 x 8 mm rim nearly away, and no plane
// of boundary points lies on what is left (the frame was 33-68 degrees off
// on seeds 3, 7, 8 and 10 of 1-12). The boundary's centroid still lies
// above the cloud's, on the axis: the frame follows it there.
TEST(Repairer, TheFrameFollowsTheBoundaryWhereTheRimIsNotchedAway) {
  RepairSteps unchecked = RepairSteps::For(RepairMode::kBest);
  unchecked.frame.max_boundary_axis_angle_rad = 0.0;
  double worst = 0.0, worst_unchecked = 0.0;
  for (uint64_t seed : {3, 7, 8, 10}) {
    synth::PaperProtocolConfig pc;
    pc.shape = synth::Shape::kEllipsoid;
    pc.top_cut_fraction = 0.02;
    pc.seed = seed;
    const synth::PaperProtocolCloud c = synth::MakePaperProtocolCloud(pc);
    const Eigen::Vector3d z_true = c.T_cloud_object.linear().col(2);
    const RepairResult r = Repair(Cloud(c.holey));
    ASSERT_EQ(r.report.status, RepairStatus::kRepaired) << seed;
    const double angle = AngleDeg(r.report.frame.T_in_V.linear().col(2), z_true);
    EXPECT_LT(angle, 8.0) << "seed " << seed;
    worst = std::max(worst, angle);
    const RepairResult u = RepairWithSteps(Cloud(c.holey), RepairConfig{}, unchecked);
    if (u.report.status == RepairStatus::kRepaired) {
      worst_unchecked = std::max(worst_unchecked, AngleDeg(u.report.frame.T_in_V.linear().col(2), z_true));
    }
  }
  std::printf("frame's axis, worst of 4 seeds: %.1f deg (without the check: %.1f)\n", worst, worst_unchecked);
  // The check is what finds these axes.
  EXPECT_GT(worst_unchecked, 20.0);
}

// A closed surface has no holes: random-sample density gaps and sharp
// edges must not be taken for hole boundaries.
TEST(Repairer, ClosedSurfaceComesBackUnchanged) {
  for (const synth::Shape shape : {synth::Shape::kSphere, synth::Shape::kCuboid, synth::Shape::kCylinder}) {
    for (const int points : {20000, 50000}) {
      const TriangleMesh mesh = synth::MakeShape(shape, synth::DefaultSize(shape));
      const mesh::SurfaceSamples s = mesh::SampleSurface(mesh, points, 3);
      const RepairResult r = Repair(Cloud(s.points));
      SCOPED_TRACE(synth::ShapeName(shape) + ", " + std::to_string(points) + " points");
      EXPECT_EQ(r.cloud.size(), s.points.size());
      EXPECT_EQ(r.report.status, RepairStatus::kNoHoles);
      EXPECT_EQ(r.report.StatusText(), "no holes found");
    }
  }
}

TEST(Repairer, TinyCloudIsANoOpWithAReason) {
  const RepairResult r = Repair(Cloud({{0, 0, 0}, {0.01f, 0, 0}, {0, 0.01f, 0}}));
  EXPECT_EQ(r.cloud.size(), 3u);
  EXPECT_EQ(r.report.status, RepairStatus::kTooFewPoints);
  EXPECT_NE(r.report.StatusText().find("too few points: "), std::string::npos);
}

TEST(Repairer, NonFiniteInputThrowsNamingThePoint) {
  std::vector<Eigen::Vector3f> points(500, Eigen::Vector3f(0.1f, 0.2f, 0.3f));
  points[17].y() = std::nanf("");
  try {
    Repair(Cloud(points));
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("point 17"), std::string::npos) << e.what();
  }
}

// A cloud repaired with its missing top towards +z (the hint a fused
// cloud's claw axis gives).
// The samples (with their normals) that `keep` keeps: a shape with a part
// never seen.
template <typename Keep>
ObjectCloud Kept(const mesh::SurfaceSamples& s, Keep keep) {
  ObjectCloud in;
  for (size_t i = 0; i < s.points.size(); ++i) {
    if (!keep(s.points[i])) continue;
    in.points_G.push_back(s.points[i]);
    in.normals_G.push_back(s.normals[i]);
  }
  return in;
}

float HighestZ(const ObjectCloud& c) {
  float z = -std::numeric_limits<float>::infinity();
  for (const Eigen::Vector3f& p : c.points_G) z = std::max(z, p.z());
  return z;
}

RepairResult RepairUp(const ObjectCloud& in) {
  RepairConfig config;
  config.up_hint = Eigen::Vector3d::UnitZ();
  return Repair(in, config);
}

// A bottle cut through its neck, seen from the cloud alone: no mirror (its
// widest section is low), no surface of revolution closes a straight neck,
// and the walls cannot tell a capped neck from an open one. The search
// leaves it open: nothing above the rim, the hole reported unobserved.
TEST(Repairer, AnOpeningNothingExplainsIsLeftOpenAndReportedUnobserved) {
  const Eigen::Vector3d size(0.07, 0.07, 0.2);
  const mesh::SurfaceSamples s = mesh::SampleSurface(synth::MakeShape(synth::Shape::kBottle, size), 30000, 9);
  // The top 10 mm of the neck cut off.
  const ObjectCloud in = Kept(s, [](const Eigen::Vector3f& p) { return p.z() <= 0.19f; });
  const float rim_z = HighestZ(in);
  const RepairResult r = RepairUp(in);
  ASSERT_EQ(r.report.status, RepairStatus::kRepaired);
  EXPECT_EQ(r.report.top_completion, "open") << r.report.symmetry_reason;
  EXPECT_GE(r.report.top_confidence, 0.5f);
  for (size_t i = in.size(); i < r.cloud.size(); ++i) {
    EXPECT_LE(r.cloud.points_G[i].z(), rim_z + 0.001f) << "added over the open rim";
  }
  const auto top = std::find_if(r.report.holes.begin(), r.report.holes.end(),
                                [](const HoleSummary& h) { return h.kind == HoleKind::kMissingSurface; });
  ASSERT_NE(top, r.report.holes.end());
  EXPECT_TRUE(top->unobserved);
  EXPECT_EQ(top->points_added, 0);
  EXPECT_EQ(top->confidence, 0.0f);
}

// A ball with its top cut off, seen from the cloud alone: a surface of
// revolution closes it, and the search takes it or the mirror, which
// explains the rim as well (so the winner's posterior against it is
// modest).
TEST(Repairer, ABallsCutTopIsClosedByTheSearch) {
  const mesh::SurfaceSamples s =
      mesh::SampleSurface(synth::MakeShape(synth::Shape::kSphere, {0.06, 0.06, 0.06}), 30000, 4);
  // The top 12 mm cut off.
  const ObjectCloud in = Kept(s, [](const Eigen::Vector3f& p) { return p.z() < 0.048f; });
  const RepairResult r = RepairUp(in);
  ASSERT_EQ(r.report.status, RepairStatus::kRepaired);
  EXPECT_NE(r.report.top_completion, "open") << r.report.symmetry_reason;
  EXPECT_GT(r.report.top_confidence, 0.5f);
  // The cap is closed: every cut point of the truth within 2 mm of the output.
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  for (const Eigen::Vector3f& p : s.points) centre += p;
  centre /= static_cast<float>(s.points.size());
  size_t cut = 0, covered = 0;
  for (const Eigen::Vector3f& p : s.points) {
    if (p.z() < 0.049f) continue;
    ++cut;
    for (size_t i = in.size(); i < r.cloud.size(); ++i) {
      if ((r.cloud.points_G[i] - p).norm() < 0.002f) {
        ++covered;
        break;
      }
    }
  }
  ASSERT_GT(cut, 500u);
  EXPECT_GT(static_cast<double>(covered) / cut, 0.98);
  // Each added point's normal points out along the radius (whichever
  // completion won: the model's own or its neighbours').
  ASSERT_EQ(r.cloud.normals_G.size(), r.cloud.size());
  for (size_t i = in.size(); i < r.cloud.size(); ++i) {
    EXPECT_NEAR((r.cloud.points_G[i] - centre).norm(), 0.03f, 0.0015f);
    const Eigen::Vector3f radial = (r.cloud.points_G[i] - centre).normalized();
    EXPECT_GT(r.cloud.normals_G[i].dot(radial), std::cos(5.0 * M_PI / 180.0)) << i;
  }
}

// A can with its lid cut off and a finger's hole in its wall, seen from
// the cloud alone: the walls run straight to the rim, so the mirror closes
// it with a lid, which a cup's mouth would leave open on the same points.
// Every point added at the top carries at most a coin flip, and so does
// the top's hole; the wall's fill keeps its own confidence.
TEST(Repairer, ALidOverStraightWallsIsACoinFlip) {
  const mesh::SurfaceSamples s =
      mesh::SampleSurface(synth::MakeShape(synth::Shape::kCylinder, {0.066, 0.066, 0.10}), 30000, 6);
  const auto in_wall_hole = [](const Eigen::Vector3f& p) {
    return p.z() > 0.03f && p.z() < 0.045f && p.x() > 0.02f && std::abs(p.y()) < 0.01f;
  };
  // The lid, never seen, and the wall's hole.
  const ObjectCloud in =
      Kept(s, [&](const Eigen::Vector3f& p) { return p.z() <= 0.0995f && !in_wall_hole(p); });
  const float rim_z = HighestZ(in);
  const RepairResult r = RepairUp(in);
  ASSERT_EQ(r.report.status, RepairStatus::kRepaired);
  ASSERT_EQ(r.report.top_completion, "mirror") << r.report.symmetry_reason;
  EXPECT_EQ(r.report.top_confidence, 0.5f);
  EXPECT_NE(r.report.symmetry_reason.find("as likely a mouth"), std::string::npos)
      << r.report.symmetry_reason;
  size_t lid = 0, wall = 0;
  for (size_t i = in.size(); i < r.cloud.size(); ++i) {
    const Eigen::Vector3f& p = r.cloud.points_G[i];
    if (p.z() > rim_z - 0.005f) {
      ++lid;
      EXPECT_LE(r.cloud.confidence[i], 0.5f) << i;
    } else if (in_wall_hole(p)) {
      ++wall;
      EXPECT_GT(r.cloud.confidence[i], 0.5f) << i;
    }
  }
  EXPECT_GT(lid, 2000u);
  EXPECT_GT(wall, 20u);
  const auto top = std::find_if(r.report.holes.begin(), r.report.holes.end(),
                                [](const HoleSummary& h) { return h.kind == HoleKind::kMissingSurface; });
  ASSERT_NE(top, r.report.holes.end());
  EXPECT_FALSE(top->unobserved);
  EXPECT_EQ(top->confidence, 0.5f);
}

// A protocol cylinder (object frame) with its true outward normals: the
// input's normals come back unchanged, the added points get normals that
// match the surface there and point out.
TEST(Repairer, KeepsInputNormalsAndEstimatesTheAddedOnes) {
  synth::PaperProtocolConfig pc;
  pc.shape = synth::Shape::kCylinder;
  pc.num_points = 30000;
  pc.random_pose = false;
  const synth::PaperProtocolCloud c = synth::MakePaperProtocolCloud(pc);
  const double height = c.size_m.z();
  const auto true_normal = [&](const Eigen::Vector3f& p) -> Eigen::Vector3f {
    if (p.z() < 1e-4) return {0, 0, -1};
    if (p.z() > height - 1e-4) return {0, 0, 1};
    return Eigen::Vector3f(p.x(), p.y(), 0).normalized();
  };
  ObjectCloud in = Cloud(c.holey);
  for (const Eigen::Vector3f& p : c.holey) in.normals_G.push_back(true_normal(p));
  const RepairResult r = Repair(in);
  ASSERT_EQ(r.report.status, RepairStatus::kRepaired);
  ASSERT_EQ(r.cloud.normals_G.size(), r.cloud.size());
  ASSERT_GT(r.cloud.size(), in.size());
  for (size_t i = 0; i < in.size(); ++i) ASSERT_EQ(r.cloud.normals_G[i], in.normals_G[i]) << i;
  // Away from the edges (3 mm) the estimate follows the surface and points
  // out; the mirrored top lies within a spacing of z = H.
  const double radius = 0.5 * c.size_m.x();
  size_t good = 0, judged = 0;
  for (size_t i = in.size(); i < r.cloud.size(); ++i) {
    const Eigen::Vector3f& n = r.cloud.normals_G[i];
    EXPECT_NEAR(n.norm(), 1.0f, 1e-4f);
    const Eigen::Vector3f& p = r.cloud.points_G[i];
    const double r_xy = std::hypot(p.x(), p.y());
    const bool cap = p.z() < 0.003 || p.z() > height - 0.003;
    const bool side = r_xy > radius - 0.003;
    if (cap == side) continue;  // near an edge
    const Eigen::Vector3f truth =
        cap ? Eigen::Vector3f(0, 0, p.z() < 0.003 ? -1 : 1) : Eigen::Vector3f(p.x(), p.y(), 0).normalized();
    ++judged;
    good += n.dot(truth) > 0.9f;
  }
  EXPECT_GT(judged, 0.5 * static_cast<double>(r.cloud.size() - in.size()));
  EXPECT_GT(good, 0.95 * static_cast<double>(judged));
  // The mirror's points take their source's normal, mirrored: on the top
  // cap (the bottom's image) it is the axis, to within a degree, where a
  // plane through neighbours tilts at the cap's edge.
  size_t on_cap = 0, along_axis = 0;
  for (size_t i = in.size(); i < r.cloud.size(); ++i) {
    if (r.cloud.provenance[i] != Provenance::kSymmetry) continue;
    const Eigen::Vector3f& p = r.cloud.points_G[i];
    if (p.z() < height - 0.001 || std::hypot(p.x(), p.y()) > radius - 0.001) continue;
    ++on_cap;
    along_axis += r.cloud.normals_G[i].z() > std::cos(M_PI / 180.0);
  }
  EXPECT_GT(on_cap, 100u);
  EXPECT_EQ(along_axis, on_cap);
  // Without input normals the output has none.
  EXPECT_TRUE(Repair(Cloud(c.holey)).cloud.normals_G.empty());
}

TEST(Repairer, EmptyCloudIsANoOp) {
  const RepairResult r = Repair(Cloud({}));
  EXPECT_EQ(r.cloud.size(), 0u);
  EXPECT_EQ(r.report.status, RepairStatus::kTooFewPoints);
  EXPECT_NE(r.report.StatusText().find("too few points: "), std::string::npos);
}

// A flat square patch: its outer edge is a boundary, but there is no
// object to close. Nothing is invented, the input comes back whole.
TEST(Repairer, FlatPatchAddsNoSymmetryAndKeepsTheInput) {
  std::vector<Eigen::Vector3f> patch;
  for (int i = 0; i < 120; ++i) {
    for (int j = 0; j < 120; ++j) patch.emplace_back(0.0008f * i, 0.0008f * j, 0.0f);
  }
  const RepairResult r = Repair(Cloud(patch));
  ASSERT_GE(r.cloud.size(), patch.size());
  for (size_t i = 0; i < patch.size(); ++i) ASSERT_EQ(r.cloud.points_G[i], patch[i]);
  for (size_t i = patch.size(); i < r.cloud.size(); ++i) {
    EXPECT_NE(r.cloud.provenance[i], Provenance::kSymmetry);
  }
  EXPECT_FALSE(r.report.symmetric);
  EXPECT_FALSE(r.report.StatusText().empty());
}

// A frustum (radius halving towards the top) with its top face cut off and
// one finger-sized hole in its side: no horizontal symmetry plane exists.
// The claw hole is still filled, nothing is mirrored, and the report says
// why.
TEST(Repairer, AsymmetricFrustumGetsItsClawHoleFilledAndNoMirror) {
  TriangleMesh mesh = synth::MakeShape(synth::Shape::kCylinder, {0.08, 0.08, 0.12});
  for (Eigen::Vector3f& v : mesh.vertices) {
    const float scale = 1.0f - 0.5f * v.z() / 0.12f;
    v.x() *= scale;
    v.y() *= scale;
  }
  const mesh::SurfaceSamples s = mesh::SampleSurface(mesh, 40000, 5);
  std::vector<Eigen::Vector3f> holey;
  for (const Eigen::Vector3f& p : s.points) {
    const bool top = p.z() > 0.12f - 1e-5f;
    const bool claw = p.x() > 0.0f && std::abs(p.y()) < 0.0125f && p.z() > 0.05f && p.z() < 0.09f;
    if (!top && !claw) holey.push_back(p);
  }
  const RepairResult r = Repair(Cloud(holey));
  ASSERT_EQ(r.report.status, RepairStatus::kRepaired);
  EXPECT_FALSE(r.report.symmetric);
  EXPECT_FALSE(r.report.symmetry_reason.empty());
  int claw_holes = 0, surface = 0, symmetry = 0;
  for (const HoleSummary& h : r.report.holes) claw_holes += h.kind == HoleKind::kClaw;
  for (size_t i = holey.size(); i < r.cloud.size(); ++i) {
    surface += r.cloud.provenance[i] == Provenance::kSurface;
    symmetry += r.cloud.provenance[i] == Provenance::kSymmetry;
  }
  std::printf("frustum: %d claw holes, %d surface points, %d mirrored; %s\n", claw_holes, surface, symmetry,
              r.report.symmetry_reason.c_str());
  EXPECT_EQ(claw_holes, 1);
  EXPECT_GT(surface, 0);
  EXPECT_EQ(symmetry, 0);
}

TEST(RepairConfig, DefaultsValidateAndBadHintIsRejected) {
  EXPECT_NO_THROW(RepairConfig{}.Validate());
  RepairConfig c;
  c.up_hint = Eigen::Vector3d::Zero();
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::repair
