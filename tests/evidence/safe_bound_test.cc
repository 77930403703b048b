#include "graspfill/evidence/safe_bound.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

#include "evidence_fixtures.hpp"

namespace graspfill::evidence {
namespace {

using testing::PlateFrame;
using testing::PointAt;
using testing::TestBox;

TEST(SafeBound, KeepsTheSurfaceAndWhatIsBehindItCarvesWhatWasSeenFree) {
  VisibilityRecord record(VisibilityConfig{}, TestBox());
  const auto f = PlateFrame();
  ASSERT_TRUE(record.Offer(f.raw, f.claw_depth, Eigen::Isometry3d::Identity()));
  const SafeBound bound = ComputeSafeBound(record);
  EXPECT_EQ(bound.nx, 120);
  EXPECT_EQ(bound.ny, 120);
  EXPECT_EQ(bound.nz, 200);
  // Every measured plate point and what lies behind it may be the object.
  for (double u = 202; u < 438; u += 13) {
    for (double v = 142; v < 338; v += 11) {
      EXPECT_TRUE(bound.Contains(PointAt(u, v, testing::kPlateDepth))) << u << "," << v;
      EXPECT_TRUE(bound.Contains(PointAt(u, v, 0.8f)));
    }
  }
  // In front of the plate and beside it the rays passed.
  EXPECT_FALSE(bound.Contains(PointAt(250, 300, 0.35f)));
  EXPECT_FALSE(bound.Contains(PointAt(100, 100, 0.8f)));
  // Behind the claw block stays in the bound.
  EXPECT_TRUE(bound.Contains(PointAt(320, 220, 0.45f)));
  EXPECT_LT(bound.count(), static_cast<size_t>(bound.nx) * bound.ny * bound.nz);
  EXPECT_FALSE(bound.Contains(Eigen::Vector3f(5, 5, 5)));
}

TEST(SafeBound, AnEmptyRecordBoundsTheWholeBox) {
  const VisibilityRecord record(VisibilityConfig{}, TestBox());
  SafeBoundConfig config;
  config.voxel_m = 0.02;
  const SafeBound bound = ComputeSafeBound(record, config);
  EXPECT_EQ(bound.count(), static_cast<size_t>(bound.nx) * bound.ny * bound.nz);
  config.voxel_m = 0.0;
  EXPECT_THROW(ComputeSafeBound(record, config), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::evidence
