// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/evidence/seen_free_carve.hpp"

#include <gtest/gtest.h>

#include "evidence_fixtures.hpp"

namespace graspfill::evidence {
namespace {

using testing::PointAt;
using testing::RecordOfPlate;
using testing::TestBox;

// A cloud of the plate's surface, a phantom layer in front of it (the ray
// passed it and measured the plate farther), points hidden behind the plate
// and a point just outside the plate's silhouette.
ObjectCloud PlateCloud() {
  ObjectCloud cloud;
  auto add = [&](const Eigen::Vector3f& p, Provenance provenance) {
    cloud.points_G.push_back(p);
    cloud.normals_G.push_back(Eigen::Vector3f(0, 0, -1));
    cloud.provenance.push_back(provenance);
  };
  add(PointAt(250, 300, 0.500f), Provenance::kObserved);   // surface: kept
  add(PointAt(250, 301, 0.492f), Provenance::kObserved);   // 8 mm in front: carved
  add(PointAt(251, 300, 0.5015f), Provenance::kObserved);  // within the noise: kept
  add(PointAt(260, 300, 0.480f), Provenance::kSymmetry);   // inferred: the repair's to judge
  add(PointAt(252, 300, 0.470f), Provenance::kObserved);   // 3 cm in front: carved
  add(PointAt(260, 310, 0.560f), Provenance::kObserved);   // behind the plate: kept
  add(PointAt(199, 300, 0.700f), Provenance::kObserved);   // the silhouette's pixel: kept
  return cloud;
}

TEST(CarveSeenFree, RemovesObservedPointsTheCameraSawThroughAndKeepsTheRestInOrder) {
  const VisibilityRecord record = RecordOfPlate();
  ObjectCloud cloud = PlateCloud();
  const ObjectCloud before = cloud;
  EXPECT_EQ(CarveSeenFree(record, &cloud), 2u);
  ASSERT_EQ(cloud.size(), 5u);
  ASSERT_EQ(cloud.normals_G.size(), 5u);
  ASSERT_EQ(cloud.provenance.size(), 5u);
  const size_t kept[] = {0, 2, 3, 5, 6};
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(cloud.points_G[i], before.points_G[kept[i]]) << i;
    EXPECT_EQ(cloud.provenance[i], before.provenance[kept[i]]) << i;
  }
  // Nothing left to carve.
  EXPECT_EQ(CarveSeenFree(record, &cloud), 0u);
}

TEST(CarveSeenFree, AnEmptyRecordOrCloudRemovesNothing) {
  ObjectCloud cloud = PlateCloud();
  EXPECT_EQ(CarveSeenFree(VisibilityRecord(VisibilityConfig{}, TestBox()), &cloud), 0u);
  EXPECT_EQ(cloud.size(), PlateCloud().size());
  ObjectCloud empty;
  EXPECT_EQ(CarveSeenFree(RecordOfPlate(), &empty), 0u);
}

TEST(CarveSeenFree, ACloudWithoutNormalsOrProvenanceIsTreatedAsObserved) {
  ObjectCloud cloud = PlateCloud();
  cloud.normals_G.clear();
  cloud.provenance.clear();
  // The inferred point of PlateCloud now counts as observed: 3 carved.
  EXPECT_EQ(CarveSeenFree(RecordOfPlate(), &cloud), 3u);
  EXPECT_EQ(cloud.size(), 4u);
  EXPECT_TRUE(cloud.normals_G.empty());
  EXPECT_TRUE(cloud.provenance.empty());
}

}  // namespace
}  // namespace graspfill::evidence
