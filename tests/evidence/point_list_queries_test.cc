// SPDX-License-Identifier: BSD-3-Clause
// The record asked about lists of points, on the plate fixture: points in
// front of the plate were seen free, points on it are surface.
#include "evidence/point_list_queries.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "evidence_fixtures.hpp"

namespace graspfill::evidence {
namespace {

using testing::PointAt;
using testing::RecordOfPlate;
using testing::TestBox;
using Points = std::vector<Eigen::Vector3f>;

constexpr int kFree = 30, kSurface = 20;

// kFree points 10 cm in front of the plate, then kSurface points on it.
Points FreeThenSurface() {
  Points points;
  for (int i = 0; i < kFree; ++i) points.push_back(PointAt(220 + 5 * i, 160, 0.40f));
  for (int i = 0; i < kSurface; ++i) points.push_back(PointAt(220 + 5 * i, 300, testing::kPlateDepth));
  return points;
}

TEST(PointListQueries, SeenFreeShareCountsTheFreePointsAndDropSeenFreeRemovesThem) {
  const VisibilityRecord record = RecordOfPlate();
  const Eigen::Isometry3f identity = Eigen::Isometry3f::Identity();
  Points points = FreeThenSurface();
  EXPECT_DOUBLE_EQ(SeenFreeShare(record, points, identity), static_cast<double>(kFree) / (kFree + kSurface));
  EXPECT_EQ(SeenFreeShare(record, Points{}, identity), 0.0);
  const Points before = points;
  EXPECT_EQ(DropSeenFree(record, identity, &points), kFree);
  // The surface points stay, in their order.
  EXPECT_EQ(points, Points(before.begin() + kFree, before.end()));
  EXPECT_EQ(SeenFreeShare(record, points, identity), 0.0);
  // One flag per point, in order: the free ones first.
  std::vector<char> expected(kFree + kSurface, 0);
  std::fill(expected.begin(), expected.begin() + kFree, 1);
  EXPECT_EQ(SeenFreeFlags(record, before, identity), expected);
  EXPECT_TRUE(SeenFreeFlags(record, Points{}, identity).empty());
}

TEST(PointListQueries, UncountedPointsAndPointsBelowTheHeightAreLeftOut) {
  const VisibilityRecord record = RecordOfPlate();
  const Eigen::Isometry3f identity = Eigen::Isometry3f::Identity();
  Points points = FreeThenSurface();
  std::vector<char> uncounted(points.size(), 0);
  std::fill(uncounted.begin(), uncounted.begin() + kFree, 1);  // the free ones left out
  EXPECT_EQ(SeenFreeShare(record, points, identity, &uncounted), 0.0);
  std::fill(uncounted.begin(), uncounted.end(), 1);  // none counted
  EXPECT_EQ(SeenFreeShare(record, points, identity, &uncounted), 0.0);
  std::fill(uncounted.begin(), uncounted.begin() + kFree, 0);  // the surface ones left out
  EXPECT_EQ(SeenFreeShare(record, points, identity, &uncounted), 1.0);
  // Here V = G: z is the depth. The free points (0.40 m) are under 0.45 m.
  EXPECT_EQ(DropSeenFree(record, identity, &points, 0.45f), 0);
  EXPECT_EQ(points.size(), static_cast<size_t>(kFree + kSurface));
  EXPECT_EQ(DropSeenFree(record, identity, &points, 0.35f), kFree);
}

TEST(PointListQueries, PointsAreMappedIntoTheRecordsFrame) {
  const VisibilityRecord record = RecordOfPlate();
  // V lies 10 cm behind G along z: V's points 0.3 m deep are G's 0.4 m
  // (seen free), V's 0.4 m are on the plate.
  const Eigen::Isometry3f T_in_V(Eigen::Translation3f(0.0f, 0.0f, 0.1f));
  Points points_V;
  for (int i = 0; i < kFree; ++i) points_V.push_back(T_in_V.inverse() * PointAt(220 + 5 * i, 160, 0.40f));
  for (int i = 0; i < kSurface; ++i) points_V.push_back(T_in_V.inverse() * PointAt(220 + 5 * i, 300, 0.5f));
  EXPECT_DOUBLE_EQ(SeenFreeShare(record, points_V, T_in_V), static_cast<double>(kFree) / (kFree + kSurface));
  EXPECT_EQ(SeenFreeFlags(record, points_V, T_in_V)[0], 1);
  EXPECT_EQ(SeenFreeFlags(record, points_V, T_in_V)[kFree], 0);
  EXPECT_EQ(DropSeenFree(record, T_in_V, &points_V), kFree);
}

// A record of no key frame holding the claw block.
VisibilityRecord RecordWithClaw() {
  VisibilityRecord record(VisibilityConfig{}, TestBox());
  record.SetClaw(testing::ClawBlock());
  return record;
}

TEST(PointListQueries, APointInTheClawIsPushedOutTowardsVsAxis) {
  const VisibilityRecord record = RecordWithClaw();
  const Eigen::Vector3f inside_G(0.005f, 0.0f, 0.5f), outside_G(0.05f, 0.0f, 0.5f);
  // V's axis 5 cm to G's -x: the point leaves the block through its -x face.
  Eigen::Isometry3f T_in_V(Eigen::Translation3f(-0.05f, 0.0f, 0.0f));
  Points points_V = {T_in_V.inverse() * inside_G, T_in_V.inverse() * outside_G};
  const Points before = points_V;
  EXPECT_EQ(PushOutOfClaw(record, T_in_V, &points_V), 1);
  EXPECT_TRUE((T_in_V * points_V[0]).isApprox(Eigen::Vector3f(-0.01f, 0.0f, 0.5f), 1e-5f));
  EXPECT_EQ(points_V[1], before[1]);
  // V's axis 5 cm to G's +x: through its +x face.
  T_in_V = Eigen::Translation3f(0.05f, 0.0f, 0.0f);
  points_V = {T_in_V.inverse() * inside_G};
  EXPECT_EQ(PushOutOfClaw(record, T_in_V, &points_V), 1);
  EXPECT_TRUE((T_in_V * points_V[0]).isApprox(Eigen::Vector3f(0.01f, 0.0f, 0.5f), 1e-5f));
  // No claw: nothing moves.
  const VisibilityRecord no_claw(VisibilityConfig{}, TestBox());
  points_V = {inside_G};
  EXPECT_EQ(PushOutOfClaw(no_claw, Eigen::Isometry3f::Identity(), &points_V), 0);
  EXPECT_EQ(points_V[0], inside_G);
}

TEST(PointListQueries, PointsInTheClawAboveTheHeightAreDropped) {
  const VisibilityRecord record = RecordWithClaw();
  const Eigen::Isometry3f identity = Eigen::Isometry3f::Identity();
  const Points points = {{0.0f, 0.0f, 0.55f}, {0.05f, 0.0f, 0.55f}, {0.0f, 0.005f, 0.45f}};
  Points p = points;
  EXPECT_EQ(DropInsideClaw(record, identity, &p, 0.5f), 1);  // the low one stays
  EXPECT_EQ(p, Points({points[1], points[2]}));
  p = points;
  EXPECT_EQ(DropInsideClaw(record, identity, &p), 2);
  EXPECT_EQ(p, Points({points[1]}));
  p = points;
  EXPECT_EQ(DropInsideClaw(VisibilityRecord(VisibilityConfig{}, TestBox()), identity, &p), 0);
  EXPECT_EQ(p, points);
}

TEST(PointListQueries, ObservedSeenFreeShareAsksTheObservedPointsOfASample) {
  const VisibilityRecord record = RecordOfPlate();
  ObjectCloud cloud;
  const auto add = [&](float z, Provenance provenance) {
    cloud.points_G.push_back(PointAt(250.0 + static_cast<double>(cloud.points_G.size()), 300, z));
    cloud.provenance.push_back(provenance);
  };
  add(0.40f, Provenance::kObserved);  // free
  add(0.50f, Provenance::kObserved);  // surface
  add(0.40f, Provenance::kObserved);  // free
  add(0.50f, Provenance::kObserved);  // surface
  add(0.40f, Provenance::kSymmetry);  // free, not observed: not asked
  EXPECT_DOUBLE_EQ(ObservedSeenFreeShare(record, cloud, 100), 0.5);
  EXPECT_DOUBLE_EQ(ObservedSeenFreeShare(record, cloud, 0), 0.5);
  // At most about two asked: every second point (0, 2, 4), 4 not observed.
  EXPECT_DOUBLE_EQ(ObservedSeenFreeShare(record, cloud, 2), 1.0);
  // No provenance: every point is observed.
  cloud.provenance.clear();
  EXPECT_DOUBLE_EQ(ObservedSeenFreeShare(record, cloud, 100), 0.6);
  EXPECT_EQ(ObservedSeenFreeShare(record, ObjectCloud{}, 100), 0.0);
}

}  // namespace
}  // namespace graspfill::evidence
