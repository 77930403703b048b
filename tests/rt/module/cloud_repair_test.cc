// SPDX-License-Identifier: BSD-3-Clause
// RepairObjectCloud: the repaired cloud as a subscriber sees it (fused
// points first, the repair's holes and "repair_" timings in the message),
// and the cloud left alone when the repair throws.
#include "module/cloud_repair.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "protocol_cloud.hpp"

namespace graspfill::rt {
namespace {

TEST(CloudRepair, AppendsTheRepairAndItsFindingsToTheFusedCloud) {
  const ObjectCloud fused = testing::MakeProtocolObjectCloud(7);
  ObjectCloud cloud = fused;
  const repair::RepairReport report = RepairObjectCloud(repair::RepairConfig{}, &cloud);
  ASSERT_EQ(report.status, repair::RepairStatus::kRepaired);
  ASSERT_TRUE(testing::FusedThenAdded(fused, cloud));
  EXPECT_EQ(cloud.seq, fused.seq);
  EXPECT_EQ(cloud.utime, fused.utime);
  ASSERT_EQ(cloud.holes.size(), report.holes.size());
  EXPECT_FALSE(cloud.holes.empty());
  // The fused cloud's timings stay first, the repair's steps follow.
  ASSERT_EQ(cloud.timings.size(), fused.timings.size() + report.timings.size());
  EXPECT_EQ(cloud.timings[0].stage, "extract");
  for (size_t i = 0; i < report.timings.size(); ++i) {
    EXPECT_EQ(cloud.timings[fused.timings.size() + i].stage, "repair_" + report.timings[i].stage);
  }
}

TEST(CloudRepair, LeavesTheCloudAsItWasWhenTheRepairThrows) {
  ObjectCloud cloud = testing::MakeProtocolObjectCloud(3);
  cloud.points_G[17].x() = std::nanf("");
  const ObjectCloud before = cloud;
  EXPECT_THROW(RepairObjectCloud(repair::RepairConfig{}, &cloud), std::invalid_argument);
  EXPECT_EQ(cloud.size(), before.size());
  EXPECT_EQ(cloud.provenance, before.provenance);
  EXPECT_TRUE(cloud.holes.empty());
  EXPECT_EQ(cloud.timings.size(), before.timings.size());
}

TEST(CloudRepair, GripperFrameConfigPointsUpTowardsThePalm) {
  repair::RepairConfig base;
  base.mode = repair::RepairMode::kPaper;
  const repair::RepairConfig config = GripperFrameRepairConfig(base);
  ASSERT_TRUE(config.up_hint.has_value());
  EXPECT_EQ(*config.up_hint, Eigen::Vector3d(0, 0, -1));
  EXPECT_EQ(config.mode, repair::RepairMode::kPaper);
}

}  // namespace
}  // namespace graspfill::rt
