// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/evidence/safe_bound.hpp"

#include <gtest/gtest.h>

#include <cmath>
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

// G turned about the box centre by `deg` about y.
Eigen::Isometry3d Turned(double deg) {
  const Eigen::Vector3d c = 0.5 * (TestBox().min_G + TestBox().max_G);
  return Eigen::Translation3d(c) * Eigen::AngleAxisd(deg * M_PI / 180.0, Eigen::Vector3d::UnitY()) *
         Eigen::Translation3d(-c);
}

TEST(SafeBound, TheRecordKeepsTheBoundAsKeyFramesComeTheSameAsComputedAnew) {
  VisibilityConfig keeps;  // keeps the bound at 1 cm
  keeps.safe_bound_voxel_m = 0.01;
  VisibilityConfig none = keeps;  // keeps none: ComputeSafeBound carves anew
  none.safe_bound_voxel_m = 0.0;
  VisibilityRecord kept(keeps, TestBox()), anew(none, TestBox());
  SafeBoundConfig config;
  config.voxel_m = 0.01;
  ASSERT_NE(kept.safe_bound(), nullptr);
  EXPECT_EQ(anew.safe_bound(), nullptr);
  EXPECT_EQ(kept.safe_bound()->count(), static_cast<size_t>(60 * 60 * 100));  // the whole box
  const auto f = PlateFrame();
  size_t previous = kept.safe_bound()->count();
  for (const double deg : {0.0, 20.0, -25.0, 45.0}) {
    ASSERT_TRUE(kept.Offer(f.raw, f.claw_depth, Turned(deg)));
    ASSERT_TRUE(anew.Offer(f.raw, f.claw_depth, Turned(deg)));
    const SafeBound computed = ComputeSafeBound(anew, config);
    EXPECT_EQ(kept.safe_bound()->bits, computed.bits) << deg;
    EXPECT_EQ(ComputeSafeBound(kept, config).bits, computed.bits);
    // Every key frame carves more of it.
    EXPECT_LT(computed.count(), previous) << deg;
    previous = computed.count();
  }
  // A snapshot keeps its bound when the record is reset.
  const VisibilityRecord snapshot = kept;
  kept.Reset();
  EXPECT_EQ(snapshot.safe_bound()->count(), previous);
  EXPECT_EQ(kept.safe_bound()->count(), static_cast<size_t>(60 * 60 * 100));
  // Another voxel than the kept one is computed anew.
  config.voxel_m = 0.02;
  EXPECT_EQ(ComputeSafeBound(snapshot, config).voxel_m, 0.02f);
  none.safe_bound_voxel_m = 0.0001;
  EXPECT_THROW(VisibilityRecord(none, TestBox()), std::invalid_argument);
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
