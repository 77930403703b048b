// SPDX-License-Identifier: BSD-3-Clause
// The repair with the camera's evidence, on a fused cloud of a synthetic
// grasp (synth -> pipeline -> repair in-process): a can held by the
// three-finger claw, whose top the camera never sees. Covers the stage
// (evidence_stage.*) through Repair, and its steps: the mirror's lowering
// and lift (mirror_evidence.*) and the top from the evidence
// (evidence_top.*).
#include "evidence_top.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>

#include "eval/metrics.hpp"
#include "evidence/point_list_queries.hpp"
#include "fused_scene.hpp"
#include "graspfill/core/percentile.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "graspfill/mesh/nearest_distances.hpp"
#include "graspfill/pipeline/pipeline.hpp"
#include "graspfill/repair/repairer.hpp"
#include "mirror_evidence.hpp"
#include "synth/renderer.hpp"
#include "synth/scene.hpp"

namespace graspfill::repair {
namespace {

struct Fused {
  ObjectCloud cloud;
  evidence::VisibilityRecord record;
  std::vector<Eigen::Vector3f> truth;
};

// One turn of a can (not the e2e suite's size) fused as a replay would.
const Fused& Can() {
  static const Fused fused = [] {
    synth::SceneConfig sc;
    sc.shape = synth::Shape::kCylinder;
    sc.size_m = Eigen::Vector3d(0.06, 0.06, 0.11);
    sc.num_frames = 45;
    sc.seed = 5;
    const synth::Scene scene(sc);
    Pipeline pipeline(PipelineConfig{}, scene.MakeClawModel());
    testing::FuseScene(scene, &pipeline);
    Fused f;
    f.cloud = pipeline.ExtractCloud();
    f.record = pipeline.visibility();
    f.truth = mesh::SampleSurface(scene.object_G(), 100000, 3).points;
    return f;
  }();
  return fused;
}

RepairConfig InG() {
  RepairConfig config;
  config.up_hint = Eigen::Vector3d(0, 0, -1);  // in G the unseen top faces the palm
  return config;
}

using testing::Coverage;

TEST(EvidenceRepair, ClosesTheCansTopAndAddsNothingInSeenFreeSpace) {
  const Fused& can = Can();
  ASSERT_GE(can.record.size(), 12u);
  const RepairResult plain = Repair(can.cloud, InG());
  const RepairResult seen = Repair(can.cloud, InG(), &can.record);
  const EvidenceReport& e = seen.report.evidence;
  ASSERT_TRUE(e.used) << e.ignored_reason;
  EXPECT_LT(e.observed_free_share, 0.01);
  ASSERT_GT(seen.cloud.size(), can.cloud.size());
  int in_free = 0;
  for (size_t i = can.cloud.size(); i < seen.cloud.size(); ++i)
    in_free += can.record.SeenFree(seen.cloud.points_G[i]);
  EXPECT_EQ(in_free, 0);
  // The fused points come first, unchanged.
  for (size_t i = 0; i < can.cloud.size(); ++i) ASSERT_EQ(seen.cloud.points_G[i], can.cloud.points_G[i]);
  const double fused = Coverage(can.cloud, can.truth), with = Coverage(seen.cloud, can.truth);
  EXPECT_LT(fused, 0.9);  // the top and the claw holes are missing
  EXPECT_GE(with, 0.97);
  EXPECT_GE(with, Coverage(plain.cloud, can.truth) - 0.005);
  // Every added point is near the true surface.
  const std::vector<Eigen::Vector3f> added(seen.cloud.points_G.begin() + static_cast<long>(can.cloud.size()),
                                           seen.cloud.points_G.end());
  EXPECT_LE(Percentile(mesh::NearestDistances(added, can.truth), 95.0), 0.002);
  // Confidence: one per point, observed 1, added below.
  ASSERT_EQ(seen.cloud.confidence.size(), seen.cloud.size());
  EXPECT_EQ(seen.cloud.confidence.front(), 1.0f);
  EXPECT_LT(seen.cloud.confidence.back(), 1.0f);
  EXPECT_GT(seen.cloud.confidence.back(), 0.0f);
}

TEST(EvidenceRepair, SafeBoundHoldsTheWholeObjectAndLittleElse) {
  const Fused& can = Can();
  const RepairResult seen = Repair(can.cloud, InG(), &can.record);
  const SafeBound& bound = seen.cloud.safe_bound;
  ASSERT_FALSE(bound.empty());
  int outside = 0;
  for (const Eigen::Vector3f& p : can.truth) outside += !bound.Contains(p);
  EXPECT_EQ(outside, 0);
  // The can's bounding cylinder is ~0.3 L; the bound is a few times that
  // (the space behind the fingers and above the top), far below the box.
  const double bound_litres = bound.count() * std::pow(bound.voxel_m, 3) * 1000.0;
  const double box_litres = bound.nx * bound.ny * bound.nz * std::pow(bound.voxel_m, 3) * 1000.0;
  EXPECT_GT(bound_litres, 0.3);
  EXPECT_LT(bound_litres, 0.2 * box_litres);
  EXPECT_EQ(seen.report.evidence.safe_bound_voxels, static_cast<int>(bound.count()));
}

TEST(EvidenceRepair, ARecordOfAnotherFrameOrNoneIsIgnoredWithTheReason) {
  const Fused& can = Can();
  ObjectCloud moved = can.cloud;
  for (Eigen::Vector3f& p : moved.points_G) p += Eigen::Vector3f(0.0f, 0.06f, 0.0f);
  const RepairResult r = Repair(moved, InG(), &can.record);
  EXPECT_FALSE(r.report.evidence.used);
  EXPECT_NE(r.report.evidence.ignored_reason.find("does not match"), std::string::npos)
      << r.report.evidence.ignored_reason;
  EXPECT_TRUE(r.cloud.safe_bound.empty());

  const evidence::VisibilityRecord empty(evidence::VisibilityConfig{}, fusion::WorkspaceBox{});
  const RepairResult e = Repair(can.cloud, InG(), &empty);
  EXPECT_FALSE(e.report.evidence.used);
  EXPECT_NE(e.report.evidence.ignored_reason.find("no key frame"), std::string::npos);
  // Ignored evidence gives the cloud-only repair.
  EXPECT_EQ(e.cloud.points_G, Repair(can.cloud, InG()).cloud.points_G);
}

TEST(EvidenceRepair, DeterministicAndPaperModeIgnoresTheRecord) {
  const Fused& can = Can();
  const RepairResult a = Repair(can.cloud, InG(), &can.record);
  const RepairResult b = Repair(can.cloud, InG(), &can.record);
  EXPECT_EQ(a.cloud.points_G, b.cloud.points_G);
  EXPECT_EQ(a.cloud.confidence, b.cloud.confidence);
  RepairConfig paper = InG();
  paper.mode = RepairMode::kPaper;
  EXPECT_FALSE(Repair(can.cloud, paper, &can.record).report.evidence.used);
}

// A mirror image capping the can too high (its top band raised into the
// space the rays passed over) is lowered until it meets the share; one
// shifted sideways (a handle's image) is contradicted at every height and
// left for the caller to refuse.
TEST(EvidenceRepair, AMirrorCappingTooHighIsLoweredASidewaysOneIsNot) {
  const Fused& can = Can();
  // V: +z towards the palm (G's -z), where the unseen top is.
  Eigen::Isometry3f T_in_V = Eigen::Isometry3f::Identity();
  T_in_V.linear() = Eigen::AngleAxisf(static_cast<float>(M_PI), Eigen::Vector3f::UnitX()).toRotationMatrix();
  const Eigen::Isometry3f T_V_in = T_in_V.inverse();
  float top_V = -1e9f;
  for (const Eigen::Vector3f& p : can.truth) top_V = std::max(top_V, (T_V_in * p).z());
  PointList cap_V;  // the true top band, 1.5 mm deep
  for (const Eigen::Vector3f& p : can.truth) {
    const Eigen::Vector3f v = T_V_in * p;
    if (v.z() > top_V - 0.0015f) cap_V.push_back(v);
  }
  ASSERT_GT(cap_V.size(), 1000u);
  EvidenceConfig config;
  const float floor_V = top_V - 0.03f;

  PointList high = cap_V;
  for (Eigen::Vector3f& p : high) p.z() += 0.006f;
  const double share_high = evidence::SeenFreeShare(can.record, high, T_in_V);
  ASSERT_GT(share_high, config.max_mirror_free_share) << "the raised cap is not contradicted";
  const double drop = LowerMirrorOutOfFree(can.record, config, T_in_V, floor_V, &high);
  ASSERT_FALSE(std::isnan(drop));
  EXPECT_GT(drop, 0.0);
  EXPECT_LE(drop, config.max_plane_drop_m + 1e-9);
  EXPECT_LE(evidence::SeenFreeShare(can.record, high, T_in_V), config.max_mirror_free_share);
  // Lowered by twice the drop, and no lower than needed: half a step less
  // was still contradicted.
  EXPECT_NEAR(high.front().z(), cap_V.front().z() + 0.006f - 2.0f * static_cast<float>(drop), 1e-6f);
  PointList less = cap_V;
  for (Eigen::Vector3f& p : less) p.z() += 0.006f - 2.0f * static_cast<float>(drop - config.top_step_m);
  EXPECT_GT(evidence::SeenFreeShare(can.record, less, T_in_V), config.max_mirror_free_share);

  PointList sideways = cap_V;  // the band 25 mm out from the wall, at all heights
  for (Eigen::Vector3f& p : sideways) p.x() += 0.025f, p.z() -= 0.03f;
  const PointList before = sideways;
  ASSERT_GT(evidence::SeenFreeShare(can.record, sideways, T_in_V), config.max_mirror_free_share);
  EXPECT_TRUE(std::isnan(LowerMirrorOutOfFree(can.record, config, T_in_V, floor_V - 0.05f, &sideways)));
  EXPECT_EQ(sideways, before);

  // Uncounted points go down with the counted ones, those under the floor
  // dropped with their flags, but do not decide the drop: points far in
  // seen-free space, uncounted, lower nothing; the raised cap, counted,
  // drops as before.
  PointList mixed = cap_V;
  mixed.insert(mixed.end(), sideways.begin(), sideways.end());
  std::vector<char> uncounted(mixed.size(), 0);
  std::fill(uncounted.begin() + static_cast<long>(cap_V.size()), uncounted.end(), 1);
  const PointList mixed_before = mixed;
  EXPECT_EQ(LowerMirrorOutOfFree(can.record, config, T_in_V, floor_V - 0.05f, &mixed, &uncounted), 0.0);
  EXPECT_EQ(mixed, mixed_before);
  high = cap_V;
  for (Eigen::Vector3f& p : high) p.z() += 0.006f;
  high.push_back(Eigen::Vector3f(0, 0, floor_V + 0.001f));  // under the floor once lowered
  high.push_back(Eigen::Vector3f(0, 0, floor_V + 0.02f));
  uncounted.assign(high.size(), 0);
  uncounted[high.size() - 2] = uncounted[high.size() - 1] = 1;
  EXPECT_EQ(LowerMirrorOutOfFree(can.record, config, T_in_V, floor_V, &high, &uncounted), drop);
  ASSERT_EQ(high.size(), cap_V.size() + 1);
  ASSERT_EQ(uncounted.size(), high.size());
  EXPECT_EQ(uncounted.back(), 1);
  EXPECT_NEAR(high.back().z(), floor_V + 0.02f - 2.0f * static_cast<float>(drop), 1e-6f);
  uncounted.pop_back();
  EXPECT_THROW(LowerMirrorOutOfFree(can.record, config, T_in_V, floor_V, &high, &uncounted),
               std::invalid_argument);
}

// The can's true top and the 20 mm of wall under it, 3 mm low: a mirror
// image of the bottom, with the plane in the middle of walls seen only up
// to a few mm under the top. The rays carve the image's cap only once it
// passes the top, so it rises to within a millimetre of it.
TEST(EvidenceRepair, ALowMirroredTopRisesUntilTheRaysCarveIt) {
  const Fused& can = Can();
  Eigen::Isometry3f T_in_V = Eigen::Isometry3f::Identity();  // V: +z towards the palm
  T_in_V.linear() = Eigen::AngleAxisf(static_cast<float>(M_PI), Eigen::Vector3f::UnitX()).toRotationMatrix();
  const Eigen::Isometry3f T_V_in = T_in_V.inverse();
  float top_V = -1e9f;
  for (const Eigen::Vector3f& p : can.truth) top_V = std::max(top_V, (T_V_in * p).z());
  constexpr float kLowM = 0.003f;
  PointList image_V;
  for (const Eigen::Vector3f& p : can.truth) {
    const Eigen::Vector3f v = T_V_in * p;
    if (v.z() > top_V - 0.02f) image_V.emplace_back(v.x(), v.y(), v.z() - kLowM);
  }
  const EvidenceConfig config;
  const double layer = 0.002;
  const ImageTop low = TopOfImage(image_V, layer);
  ASSERT_GT(low.layer_points, config.min_cap_points);
  EXPECT_NEAR(low.cap_z_V, top_V - kLowM, 0.001f);
  const double lift = MirrorLiftFromCarving(can.record, config, T_in_V, low, image_V);
  ASSERT_FALSE(std::isnan(lift)) << "no ray passes over the can's top";
  std::printf("lifted %.2f mm; the cap %.2f mm from the true top\n", 1000 * lift,
              1000 * (low.cap_z_V + lift - top_V));
  EXPECT_NEAR(low.cap_z_V + lift, top_V, 0.001);
  // Stretched there, the image's cap sits on the top and its walls stay.
  PointList raised = image_V;
  StretchImageTop(low, low.cap_z_V + static_cast<float>(lift), config, &raised);
  EXPECT_NEAR(TopOfImage(raised, layer).cap_z_V, low.cap_z_V + lift, 1e-4);
  for (size_t i = 0; i < image_V.size(); ++i) {
    if (image_V[i].z() < low.cap_z_V - 2 * config.top_band_m) {
      ASSERT_EQ(raised[i], image_V[i]);
    }
  }
  // A cap already on the top is not raised past the onset of the carve.
  PointList on_top = image_V;
  for (Eigen::Vector3f& p : on_top) p.z() += kLowM;
  EXPECT_LE(MirrorLiftFromCarving(can.record, config, T_in_V, TopOfImage(on_top, layer), on_top), 0.001);
  // No answer when the test cannot tell: a reach short of the carve, or a
  // top layer of a few points.
  EvidenceConfig short_reach;
  short_reach.max_mirror_lift_m = 0.001;
  EXPECT_TRUE(std::isnan(MirrorLiftFromCarving(can.record, short_reach, T_in_V, low, image_V)));
  EvidenceConfig many;
  many.min_cap_points = low.layer_points + 1;
  EXPECT_TRUE(std::isnan(MirrorLiftFromCarving(can.record, many, T_in_V, low, image_V)));
}

// A ball of radius 30 mm sampled on a ~1 mm Fibonacci lattice, up to
// `cut`(p) <= 0: an open top the flat cap refuses (the walls close in).
PointList Ball(const std::function<bool(const Eigen::Vector3f&)>& kept) {
  constexpr double kRadiusM = 0.03;
  constexpr int kCount = 11000;  // 4 pi R^2 / 1 mm^2
  PointList points;
  for (int i = 0; i < kCount; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / kCount;
    const double r = std::sqrt(1.0 - z * z), phi = i * 2.399963229728653;
    const Eigen::Vector3f p =
        (kRadiusM * Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z)).cast<float>();
    if (kept(p)) points.push_back(p);
  }
  return points;
}

double OffBall(const Eigen::Vector3f& p) { return std::abs(p.norm() - 0.03f); }

TEST(EvidenceRepair, ARoundTopGetsADomeOnTheBall) {
  // The top 6 mm open: a hole 36 mm across that the taper test refuses to
  // cap flat. With nothing seen (no evidence) the dome alone closes it.
  const PointList open = Ball([](const Eigen::Vector3f& p) { return p.z() <= 0.024f; });
  const evidence::VisibilityRecord nothing_seen;
  const EvidenceTop top = CloseTopFromEvidence(NeighborIndex(open), {}, nothing_seen,
                                               Eigen::Isometry3f::Identity(), 0.001, EvidenceConfig{});
  ASSERT_EQ(top.outcome, TopEvidence::kDome);
  ASSERT_GT(top.added_V.size(), 300u);  // the cap is ~1,100 mm^2
  double worst = 0.0;
  for (const Eigen::Vector3f& p : top.added_V) worst = std::max(worst, OffBall(p));
  EXPECT_LT(worst, 0.0015);  // a paraboloid over a 36 mm cap of a 60 mm ball
  // Its surface gives its points their normals: the ball's radius.
  ASSERT_TRUE(top.dome.has_value());
  for (const Eigen::Vector3f& p : top.added_V) {
    EXPECT_GT(top.dome->Normal(p).dot(p.normalized()), std::cos(3.0 * M_PI / 180.0)) << p.transpose();
  }
  // Every spot of the missing cap is within 2 mm of a dome point.
  const PointList cap = Ball([](const Eigen::Vector3f& p) { return p.z() > 0.024f; });
  EXPECT_GE(eval::FractionWithin(mesh::NearestDistances(cap, top.added_V), 0.002), 0.97);
  // Without the dome the same top stays open.
  EvidenceConfig no_dome;
  no_dome.dome_support_m = 0.0;
  const EvidenceTop flat = CloseTopFromEvidence(NeighborIndex(open), {}, nothing_seen,
                                                Eigen::Isometry3f::Identity(), 0.001, no_dome);
  EXPECT_EQ(flat.outcome, TopEvidence::kTapered);
  EXPECT_TRUE(flat.added_V.empty());
  // Asked for the outcome alone (a caller that refits the dome), the same
  // outcome and heights, and no points.
  const EvidenceTop found = CloseTopFromEvidence(
      NeighborIndex(open), {}, nothing_seen, Eigen::Isometry3f::Identity(), 0.001, EvidenceConfig{}, true);
  EXPECT_EQ(found.outcome, TopEvidence::kDome);
  EXPECT_EQ(found.top_z_V, top.top_z_V);
  EXPECT_EQ(found.wall_top_z_V, top.wall_top_z_V);
  EXPECT_TRUE(found.added_V.empty());
  EXPECT_EQ(found.rejected_free, 0);
  const EvidenceTop no_dome_found = CloseTopFromEvidence(NeighborIndex(open), {}, nothing_seen,
                                                         Eigen::Isometry3f::Identity(), 0.001, no_dome, true);
  EXPECT_EQ(no_dome_found.outcome, TopEvidence::kTapered);
}

// The highest points seen lie to one side of a round top (the cut tilted
// 20 degrees): the top band's outline (5 mm) stops short of the apex, the
// dome's support (12 mm) surrounds it. The dome stands over its support's
// outline, so the cap is closed (the apple at seed 12, 90 frames, kept its
// top's middle open: 3% of its surface).
TEST(EvidenceRepair, ADomeClosesARoundTopSeenHighestOnOneSide) {
  const Eigen::Vector3f tilt(std::sin(0.35f), 0.0f, std::cos(0.35f));
  const PointList open = Ball([&](const Eigen::Vector3f& p) { return p.dot(tilt) <= 0.022f; });
  const EvidenceTop top = CloseTopFromEvidence(NeighborIndex(open), {}, evidence::VisibilityRecord{},
                                               Eigen::Isometry3f::Identity(), 0.001, EvidenceConfig{});
  ASSERT_EQ(top.outcome, TopEvidence::kDome);
  double worst = 0.0;
  for (const Eigen::Vector3f& p : top.added_V) worst = std::max(worst, OffBall(p));
  EXPECT_LT(worst, 0.0015);
  // The missing cap round the apex (within 15 mm of it) is closed.
  const PointList cap = Ball([&](const Eigen::Vector3f& p) {
    return p.dot(tilt) > 0.022f && (p - Eigen::Vector3f(0.0f, 0.0f, 0.03f)).norm() < 0.015f;
  });
  ASSERT_GT(cap.size(), 100u);
  EXPECT_GE(eval::FractionWithin(mesh::NearestDistances(cap, top.added_V), 0.002), 0.97);
  // No dome point stands over the dome's support (a second layer): none
  // lies within 0.9 mm of a support point in x-y.
  float z_wall = 0.0f;
  for (const Eigen::Vector3f& q : open) z_wall = std::max(z_wall, q.z());
  int over_seen = 0;
  for (const Eigen::Vector3f& p : top.added_V) {
    for (const Eigen::Vector3f& q : open) {
      if (q.z() >= z_wall - 0.012f && (p - q).head<2>().norm() < 0.0009f) {
        ++over_seen;
        break;
      }
    }
  }
  EXPECT_EQ(over_seen, 0);
}

TEST(EvidenceRepair, ADomeNeverLeavesTheBallWhereItsApexIsNotOverTheHole) {
  // Cut at 40 degrees: the highest points are a crescent on one side, the
  // band's paraboloid peaks off it. Whatever comes out stays on the ball.
  const Eigen::Vector3f tilt(std::sin(0.7f), 0.0f, std::cos(0.7f));
  const PointList open = Ball([&](const Eigen::Vector3f& p) { return p.dot(tilt) <= 0.02f; });
  const EvidenceTop top = CloseTopFromEvidence(NeighborIndex(open), {}, evidence::VisibilityRecord{},
                                               Eigen::Isometry3f::Identity(), 0.001, EvidenceConfig{});
  for (const Eigen::Vector3f& p : top.added_V) ASSERT_LT(OffBall(p), 0.0015) << p.transpose();
}

// A rounded box hanging 20 degrees off the claw's axis (the zoo's soft
// box: three-finger claw, oblique grasp, 60 frames: two thirds of a turn).
// Its rim never closes into a line, so V comes from the hint, the claw's
// axis; its straight side walls turn V onto the box's own. With the
// 10-degree limit alone V stays on the claw's axis, the top looks tapered
// and nothing is added (coverage 0.893, the fused cloud's).
TEST(EvidenceRepair, ABoxHangingTiltedInTheGraspIsClosedAlongItsOwnAxis) {
  synth::SceneConfig sc;
  sc.shape = synth::Shape::kRoundedBox;
  sc.claw = synth::ClawType::kThreeFinger;
  sc.grasp = synth::GraspWay::kTopOblique;
  sc.num_frames = 60;
  sc.seed = 11;
  const synth::Scene scene(sc);
  Pipeline pipeline(PipelineConfig{}, scene.MakeClawModel());
  testing::FuseScene(scene, &pipeline);
  const ObjectCloud fused = pipeline.ExtractCloud();
  const std::vector<Eigen::Vector3f> truth = mesh::SampleSurface(scene.object_G(), 100000, 3).points;
  const RepairResult r = Repair(fused, InG(), &pipeline.visibility());
  const Eigen::Vector3d axis_V = r.report.frame.T_in_V.linear().col(2);
  const Eigen::Vector3d axis_true = scene.placement().T_G_O.linear().col(2);  // O's up
  const double off_deg = std::acos(std::min(1.0, std::abs(axis_V.dot(axis_true)))) * 180.0 / M_PI;
  const double cov = Coverage(r.cloud, truth);
  std::printf("V %.1f degrees off the box's axis, coverage %.3f (fused %.3f)\n", off_deg, cov,
              Coverage(fused, truth));
  EXPECT_LT(off_deg, 2.0);
  EXPECT_GE(cov, 0.97);
  EXPECT_GT(r.cloud.size(), fused.size());
  for (size_t i = fused.size(); i < r.cloud.size(); ++i) {
    ASSERT_FALSE(pipeline.visibility().SeenFree(r.cloud.points_G[i]));
  }
}

// Held out from the zoo's tables (seeds other than 11), two boxes hanging
// 20 degrees off the claw's axis, fused in-process as `bench repair
// --pipeline --seed S` does.
struct HeldOut {
  ObjectCloud fused;
  RepairResult repaired;
  std::vector<Eigen::Vector3f> truth;
  double coverage{0.0}, added_p95_mm{0.0}, added_wrong{0.0};
};

HeldOut RepairHeldOut(synth::Shape shape, const Eigen::Vector3d& size_m, synth::ClawType claw, int frames,
                      uint64_t seed, synth::GraspWay grasp = synth::GraspWay::kTopOblique,
                      double camera_elevation_deg = synth::MotionConfig{}.camera_elevation_deg) {
  synth::SceneConfig sc;
  sc.motion.camera_elevation_deg = camera_elevation_deg;
  sc.shape = shape;
  sc.size_m = size_m;
  sc.claw = claw;
  sc.grasp = grasp;
  sc.num_frames = frames;
  sc.seed = seed;
  const synth::Scene scene(sc);
  Pipeline pipeline(PipelineConfig{}, scene.MakeClawModel());
  testing::FuseScene(scene, &pipeline);
  HeldOut h;
  h.fused = pipeline.ExtractCloud();
  h.truth = mesh::SampleSurface(scene.object_G(), 100000, 3).points;
  h.repaired = Repair(h.fused, InG(), &pipeline.visibility());
  h.coverage = Coverage(h.repaired.cloud, h.truth);
  const std::vector<Eigen::Vector3f> added(
      h.repaired.cloud.points_G.begin() + static_cast<long>(h.fused.size()), h.repaired.cloud.points_G.end());
  if (!added.empty()) {
    const std::vector<double> d = mesh::NearestDistances(added, h.truth);
    h.added_p95_mm = 1000.0 * Percentile(d, 95.0);
    h.added_wrong = 1.0 - eval::FractionWithin(d, 0.003);
  }
  for (const Eigen::Vector3f& p : added) EXPECT_FALSE(pipeline.visibility().SeenFree(p));
  std::printf("coverage %.3f (fused %.3f), added %zu: p95 %.2f mm, %.1f%% over 3 mm; lift %.1f mm\n  %s\n",
              h.coverage, Coverage(h.fused, h.truth), added.size(), h.added_p95_mm, 100.0 * h.added_wrong,
              1000.0 * h.repaired.report.evidence.mirror_lift_m, h.repaired.report.symmetry_reason.c_str());
  return h;
}

// Issue 7's targets for a closed, roughly symmetric object.
void ExpectTargets(const HeldOut& h) {
  EXPECT_GE(h.coverage, 0.97);
  EXPECT_LE(h.added_p95_mm, 2.0);
  EXPECT_LE(h.added_wrong, 0.02);
}

// The soft box (rounded edges, three-finger claw), seed 13, 60 frames.
// Its mirrored top closed 3.7 mm under the true one, and the evidence's
// ring top, from the top band's hull, which a rounded edge leaves outside
// the box near the top, was lower still: 47% of the added points were
// over 3 mm off (coverage 0.916). Its own cap raised until the rays carve
// it lands on the top.
TEST(EvidenceRepair, ARoundedBoxsMirroredTopRisesToWhereTheRaysCarveIt) {
  const HeldOut h = RepairHeldOut(synth::Shape::kRoundedBox, Eigen::Vector3d::Zero(),
                                  synth::ClawType::kThreeFinger, 60, 13);
  EXPECT_GT(h.repaired.report.evidence.mirror_lift_m, 0.002);
  EXPECT_NE(h.repaired.report.symmetry_reason.find("where the rays carve it"), std::string::npos);
  ExpectTargets(h);
}

// A 50 x 70 x 120 mm box in the parallel claw, seed 12, 90 frames: each
// finger's pad opens into the missing top, the boundary links both pads
// through the rim into one claw hole on two opposite faces, which no
// surface fit explains, and it stayed open (coverage 0.942-0.951). The
// mirror image, accepted for the top, fills it.
TEST(EvidenceRepair, FingerHolesOpeningIntoTheTopAreFilledByTheMirror) {
  const HeldOut h = RepairHeldOut(synth::Shape::kCuboid, Eigen::Vector3d(0.05, 0.07, 0.12),
                                  synth::ClawType::kParallel, 90, 12);
  EXPECT_GE(h.repaired.report.claw_holes_left_open, 1);
  EXPECT_NE(h.repaired.report.symmetry_reason.find("claw hole"), std::string::npos);
  ExpectTargets(h);
}

// The zoo's soda can (three-finger claw, top grasp), seed 15, 90 frames:
// the three finger pads open into the top, and their sides never link
// into a line (443 boundary points, the rim's 149 used); the pads stayed
// open (coverage 0.946). The loose boundary points, in clusters, mark
// them for the mirror.
TEST(EvidenceRepair, FingerPadsTheLinkingMissedAreFilledByTheMirror) {
  const HeldOut h = RepairHeldOut(synth::Shape::kCylinder, Eigen::Vector3d(0.066, 0.066, 0.122),
                                  synth::ClawType::kThreeFinger, 90, 15, synth::GraspWay::kTopStraight);
  EXPECT_NE(h.repaired.report.symmetry_reason.find("claw hole"), std::string::npos);
  ExpectTargets(h);
}

// The zoo's pudding box (90 x 35 x 110 mm, rounded edges, parallel claw,
// top grasp), seed 15, 90 frames: the claw fills, ~1 mm proud of the
// narrow faces and past their corners, widened the claw zone's sections
// by 3-9%; no longer a constant section, its plane went 35 mm up, the
// mirror was refused and the ring top closed 3.5 mm low (coverage 0.898).
TEST(EvidenceRepair, APuddingBoxsClawFillsDoNotRaiseItsSymmetryPlane) {
  const HeldOut h = RepairHeldOut(synth::Shape::kRoundedBox, Eigen::Vector3d(0.09, 0.035, 0.11),
                                  synth::ClawType::kParallel, 90, 15, synth::GraspWay::kTopStraight);
  EXPECT_TRUE(h.repaired.report.symmetric) << h.repaired.report.symmetry_reason;
  ExpectTargets(h);
}

// The same box at seed 16: a finger's hole opens into the top, its
// boundary takes 25 mm of the top's rim, and the thin plate over that
// rim's shadow crossed under the top, 3-9 mm inside the box (440 points,
// 11.6% of the added ones over 3 mm off). Fill samples deep inside the
// observed outline at their height are dropped.
TEST(EvidenceRepair, AClawFillUnderTheTopIsDropped) {
  const HeldOut h = RepairHeldOut(synth::Shape::kRoundedBox, Eigen::Vector3d(0.09, 0.035, 0.11),
                                  synth::ClawType::kParallel, 90, 16, synth::GraspWay::kTopStraight);
  ExpectTargets(h);
}

// The zoo's tall box (50 x 70 x 120 mm, three-finger claw, held
// obliquely), seed 17, 60 frames: its mirrored cap closed 2 mm low. The
// carve would raise it 1 mm, the rings' top lay 0.8 mm over the cap, in
// agreement with the carve, so the rings stood; the image rose to them
// only from 1 mm under them, and stayed (added p95 2.03 mm).
TEST(EvidenceRepair, AMirroredTopRisesToTheRingsTheRaysConfirm) {
  const HeldOut h = RepairHeldOut(synth::Shape::kCuboid, Eigen::Vector3d(0.05, 0.07, 0.12),
                                  synth::ClawType::kThreeFinger, 60, 17);
  EXPECT_GT(h.repaired.report.evidence.mirror_lift_m, 0.0005);
  ExpectTargets(h);
}

// The zoo's ball (70 mm, three-finger claw, top grasp), seed 17, 90
// frames: a finger's hole opens into the round top, its fill is sampled
// over its rim's box, which reaches over the rim into the cap, and the
// surface fitted to the side below sagged there: 67 samples 3-4 mm inside
// (2.3-2.5% of the added points over 3 mm off). Fills above the top's rim
// and inside its outline are the top's.
TEST(EvidenceRepair, AFingerHolesFillStopsAtARoundTopsRim) {
  const HeldOut h = RepairHeldOut(synth::Shape::kSphere, Eigen::Vector3d::Constant(0.07),
                                  synth::ClawType::kThreeFinger, 90, 17, synth::GraspWay::kTopStraight);
  ExpectTargets(h);
}

// The zoo's apple (a lumpy blob, three-finger claw, top grasp), seed 18,
// 90 frames: its image stands 1.3-1.9 mm proud of its seen top half in
// places, where near-grazing rays see it free (121 points, 7% of it); the
// plane was lowered 0.5 mm for them and the whole image sank inside
// (added p95 2.57 mm, coverage 0.971). Only the image not beside the
// observed surface decides a lowering.
TEST(EvidenceRepair, AnImageProudOfTheSeenSurfaceIsNotLowered) {
  const HeldOut h = RepairHeldOut(synth::Shape::kBlob, Eigen::Vector3d::Zero(), synth::ClawType::kThreeFinger,
                                  90, 18, synth::GraspWay::kTopStraight);
  EXPECT_TRUE(h.repaired.report.symmetric);
  EXPECT_EQ(h.repaired.report.evidence.mirror_plane_drop_m, 0.0);
  ExpectTargets(h);
}

// The zoo's apple (three-finger claw, top grasp), seed 12, 90 frames: the
// bottom's middle was never seen, so its mirror image leaves the top's
// middle open (3% of the surface, coverage 0.969), and the highest points
// seen lie to one side of it. The dome, over its support's outline, now
// also closes the columns the image leaves open, fitted to the seen band
// and the image together (over the seen band alone it sagged 1.6 mm,
// median, under the apple's top: added p95 2.0008 mm).
TEST(EvidenceRepair, AMirroredRoundTopsOpenMiddleGetsTheDome) {
  const HeldOut h = RepairHeldOut(synth::Shape::kBlob, Eigen::Vector3d::Zero(), synth::ClawType::kThreeFinger,
                                  90, 12, synth::GraspWay::kTopStraight);
  EXPECT_TRUE(h.repaired.report.symmetric) << h.repaired.report.symmetry_reason;
  EXPECT_EQ(h.repaired.report.evidence.top, "dome");
  EXPECT_GE(h.coverage, 0.99);
  ExpectTargets(h);
  // A round top the walls narrow towards is not a coin flip.
  EXPECT_GT(h.repaired.report.top_confidence, 0.5f);
  // The dome's points (the top's surface points, at the search's
  // confidence; the claw fills have their own) lie nearer the apple's top.
  const ObjectCloud& cloud = h.repaired.cloud;
  std::vector<Eigen::Vector3f> dome;
  for (size_t i = h.fused.size(); i < cloud.size(); ++i) {
    if (cloud.provenance[i] == Provenance::kSurface &&
        cloud.confidence[i] == h.repaired.report.top_confidence) {
      dome.push_back(cloud.points_G[i]);
    }
  }
  ASSERT_GT(dome.size(), 100u);
  const double median_mm = 1000.0 * Percentile(mesh::NearestDistances(dome, h.truth), 50.0);
  std::printf("dome: %zu points, median %.2f mm off the apple\n", dome.size(), median_mm);
  EXPECT_LT(median_mm, 1.5);  // 1.53 over the seen band alone
}

// The zoo's bowl (open, parallel claw, top grasp), seed 11, 60 frames: its
// top band looks tapered, and its top 12 mm (the rim over an upright wall)
// curve down on every side, but a paraboloid explains them only to 2.4 mm
// RMS. Over the outline of those points the dome, moved onto the wall's
// sphere, capped the opening: 22% of the added points over 3 mm. An open
// object gets nothing wrong.
TEST(EvidenceRepair, ABowlsUprightRimGetsNoDome) {
  const HeldOut h = RepairHeldOut(synth::Shape::kBowl, Eigen::Vector3d::Zero(), synth::ClawType::kParallel,
                                  60, 11, synth::GraspWay::kTopStraight);
  EXPECT_NE(h.repaired.report.evidence.top, "dome");
  EXPECT_LE(h.added_wrong, 0.02);
  EXPECT_GE(h.coverage, Coverage(h.fused, h.truth));
}

// The zoo's bottle (70 mm body, 24 mm neck, three-finger claw, top
// grasp), seed 14, 90 frames: a finger's hole on the neck climbs the
// shoulder, and the surface fitted over it bulged 3-5 mm out of the neck
// (4.7% of the added points over 3 mm, p95 2.74 mm). V's axis, tilted by
// the body, passes 2-3 mm from the neck's: each slab's own centre bounds
// the fill by the widest observed point around it.
// The same bowl seen from a camera 25 degrees above it (a camera over the
// workspace): the rays reach into it past the palm, so nothing the record
// holds says "closed", and nothing may close it.
TEST(EvidenceRepair, ABowlSeenFromAboveStaysOpen) {
  const HeldOut h = RepairHeldOut(synth::Shape::kBowl, Eigen::Vector3d::Zero(), synth::ClawType::kParallel,
                                  90, 11, synth::GraspWay::kTopStraight, -25.0);
  EXPECT_LE(h.added_wrong, 0.02);
  EXPECT_GE(h.coverage, Coverage(h.fused, h.truth));
  EXPECT_GT(Coverage(h.fused, h.truth), 0.7);  // the inside seen: 0.52 from below
}

// The zoo's apple (three-finger claw, top grasp), seed 15, 60 frames: the
// blob leans, so the mirror image of its lower half lay 1-3 mm inside its
// upper shoulders on one side, where it filled the fingers' holes (314 of
// its 2,240 points over 2 mm off, added p95 2.36 mm). Moved onto the walls
// seen around them, the image fills them on the surface.
TEST(EvidenceRepair, ALeaningFruitsImageIsMovedOntoItsSeenWalls) {
  const HeldOut h = RepairHeldOut(synth::Shape::kBlob, Eigen::Vector3d::Zero(), synth::ClawType::kThreeFinger,
                                  60, 15, synth::GraspWay::kTopStraight);
  EXPECT_TRUE(h.repaired.report.symmetric) << h.repaired.report.symmetry_reason;
  ExpectTargets(h);
  EXPECT_LT(h.added_p95_mm, 1.5);
}

// The zoo's plum (55 mm, parallel claw, top grasp), seed 15, 60 frames:
// its outlines differ from their mirror images by 6% (the fingers' dents,
// a lean), over the cloud's 5%, so the mirror was refused, and the
// fingers' holes, which open into the top, stayed open (coverage 0.970,
// just under the target). With the record the cloud's check lets it
// through up to 10% and the record judges the image: none of it is seen
// free.
TEST(EvidenceRepair, ARecordLetsThroughAMirrorTheOutlinesNarrowlyRefuse) {
  const HeldOut h = RepairHeldOut(synth::Shape::kBlob, Eigen::Vector3d(0.055, 0.05, 0.055),
                                  synth::ClawType::kParallel, 60, 15, synth::GraspWay::kTopStraight);
  EXPECT_TRUE(h.repaired.report.symmetric) << h.repaired.report.symmetry_reason;
  ExpectTargets(h);
  EXPECT_GT(h.coverage, 0.98);  // the holes filled (0.970 open)
}

// The zoo's bottle, seed 14, 90 frames: a claw fill over the neck hole
// climbing the shoulder bulged 3-5 mm out (4.7% of the added points over
// 3 mm, p95 2.74 mm) until fills were kept within
// ClawRepairConfig::max_outside_widest_m of the widest observed point
// (1.0%, 1.60 mm). Since the fused cloud is carved where the camera saw
// through it (seen_free_carve.hpp) the fill comes out 2.6% wrong, p95
// 2.56 mm, all of it on the claw fill at the widest section: a known
// regression of this zoo case (the scanned objects gained 20 rows). Since
// the top's search (top_search.hpp) the neck's unseen end is left open
// (the walls cannot tell a capped neck from an open one), and its flat cap,
// right here and 40% of the added points, no longer dilutes the fill: the
// fill alone is 6.1% wrong, p95 3.08 mm. Held at that, and the neck open.
TEST(EvidenceRepair, AFillOverANarrowNeckStaysWithinItsWidestSeenPoint) {
  const HeldOut h = RepairHeldOut(synth::Shape::kBottle, Eigen::Vector3d::Zero(),
                                  synth::ClawType::kThreeFinger, 90, 14, synth::GraspWay::kTopStraight);
  EXPECT_EQ(h.repaired.report.top_completion, "open") << h.repaired.report.symmetry_reason;
  EXPECT_GE(h.coverage, 0.97);
  EXPECT_LE(h.added_p95_mm, 3.1);
  EXPECT_LE(h.added_wrong, 0.065);
}

// The zoo's tuna can (85 mm wide, 45 mm tall, parallel claw, top grasp),
// seed 14, 90 frames: a few rim points 3-5 mm over the rest, far from
// the pads, hid three of the pads' four sides from the classification;
// one pad became rim, the missing surface reached the can's bottom half,
// the mirror was refused (86% of its image seen free) and both pads
// stayed open (coverage 0.966).
TEST(EvidenceRepair, BothPadsOfAShortCanAreFilled) {
  const HeldOut h = RepairHeldOut(synth::Shape::kCylinder, Eigen::Vector3d(0.085, 0.085, 0.045),
                                  synth::ClawType::kParallel, 90, 14, synth::GraspWay::kTopStraight);
  EXPECT_TRUE(h.repaired.report.symmetric) << h.repaired.report.symmetry_reason;
  ExpectTargets(h);
}

// The zoo's cereal box (90 x 50 x 160 mm, three-finger claw, middle
// grasp), seed 11, 60 frames: where a few points beside a finger widen the
// top band's hull past the wall, the rays carve a share of the rings that
// rises slowly towards the top. Over the wall's baseline alone the jump
// came at the highest fused point, and the palm-side face closed there
// (added p95 2.02 mm); taken against the ring 1.5 mm lower as well, it
// comes 1.5 mm higher.
TEST(EvidenceRepair, ATopIsWhereTheRingsJumpNotWhereTheyCreep) {
  const HeldOut h = RepairHeldOut(synth::Shape::kCuboid, Eigen::Vector3d(0.09, 0.05, 0.16),
                                  synth::ClawType::kThreeFinger, 60, 11, synth::GraspWay::kMiddleStraight);
  EXPECT_EQ(h.repaired.report.evidence.top, TopEvidenceName(TopEvidence::kHeightFound));
  EXPECT_LE(h.added_p95_mm, 1.5);
  ExpectTargets(h);
}

Eigen::Vector3f OnCircle(double r, double angle, double z) {
  return Eigen::Vector3f(static_cast<float>(r * std::cos(angle)), static_cast<float>(r * std::sin(angle)),
                         static_cast<float>(z));
}

// Walls r(z) = r_bottom + (r_top - r_bottom) z / h, 0 <= z <= h, and the
// bottom disc, sampled ~1 mm apart (V: the top missing).
PointList OpenWalls(double r_bottom, double r_top, double h) {
  PointList points;
  for (double z = 0.0; z <= h; z += 0.001) {
    const double r = r_bottom + (r_top - r_bottom) * z / h;
    for (double a = 0.0; a < 2.0 * M_PI; a += 0.001 / r) points.push_back(OnCircle(r, a, z));
  }
  for (double r = 0.001; r < r_bottom; r += 0.001) {
    for (double a = 0.0; a < 2.0 * M_PI; a += 0.001 / r) points.push_back(OnCircle(r, a, 0.0));
  }
  return points;
}

// The extrusion's test of the walls: a can's walls are its top's outline
// all the way down; a cup's, narrowing 8 mm to its bottom, are not (by
// the taper's RMS over the height, ~4 mm).
TEST(EvidenceRepair, APrismsWallsFitTheExtrusionOfItsTopACupsDoNot) {
  const Fused& can = Can();
  const auto misfit = [&](double r_bottom) {
    const PointList walls = OpenWalls(r_bottom, 0.03, 0.08);
    return CloseTopFromEvidence(NeighborIndex(walls), {}, can.record, Eigen::Isometry3f::Identity(), 0.001,
                                {})
        .extrusion_rms_m;
  };
  EXPECT_LT(misfit(0.03), 0.0005);
  const double cup = misfit(0.022);
  EXPECT_GT(cup, 0.003);
  EXPECT_LT(cup, 0.006);
}

TEST(EvidenceRepair, TopWithoutOutlineAndBadConfig) {
  const Fused& can = Can();
  // Points on a line: no outline to close.
  const PointList line = {{0.0f, 0.0f, 0.01f}, {0.01f, 0.0f, 0.01f}, {0.02f, 0.0f, 0.01f}};
  const EvidenceTop none =
      CloseTopFromEvidence(NeighborIndex(line), {}, can.record, Eigen::Isometry3f::Identity(), 0.001, {});
  EXPECT_EQ(none.outcome, TopEvidence::kNoOutline);
  EXPECT_TRUE(none.added_V.empty());
  EvidenceConfig bad;
  bad.top_step_m = 0.0;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  bad = EvidenceConfig{};
  bad.max_mirror_free_share = 2.0;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  bad = EvidenceConfig{};
  bad.max_outline_mismatch = -0.01;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  bad = EvidenceConfig{};
  bad.max_plane_drop_m = -0.001;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  bad = EvidenceConfig{};
  bad.near_observed_m = -0.001;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  bad = EvidenceConfig{};
  bad.dome_support_m = -0.001;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  bad = EvidenceConfig{};
  bad.max_cap_free_share = -0.1;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  bad = EvidenceConfig{};
  bad.min_cap_points = 0;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  bad = EvidenceConfig{};
  bad.ring_trust_m = -0.001;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  for (double window : {-0.001, 0.031}) {  // beyond the search (0.03)
    bad = EvidenceConfig{};
    bad.top_jump_window_m = window;
    EXPECT_THROW(bad.Validate(), std::invalid_argument);
  }
}

}  // namespace
}  // namespace graspfill::repair
