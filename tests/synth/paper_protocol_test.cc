// SPDX-License-Identifier: BSD-3-Clause
#include "synth/paper_protocol.hpp"

#include <gtest/gtest.h>

namespace graspfill::synth {
namespace {

TEST(PaperProtocol, CutsTheTopAndThreeClawHolesOnly) {
  PaperProtocolConfig config;
  config.shape = Shape::kCylinder;
  config.random_pose = false;
  const PaperProtocolCloud c = MakePaperProtocolCloud(config);
  ASSERT_EQ(c.ground_truth.size(), static_cast<size_t>(config.num_points));
  const double top_z = TopCutZ(config, c.size_m.z());
  int above = 0;
  for (const Eigen::Vector3f& p : c.holey) above += p.z() > top_z;
  EXPECT_EQ(above, 0);
  // Each hole is empty around its centre, and the opposite side is not.
  for (const Eigen::Vector3d& centre : c.claw_hole_centres) {
    int near_hole = 0, near_mirror = 0;
    const Eigen::Vector3d mirror(-centre.x(), -centre.y(), centre.z());
    for (const Eigen::Vector3f& p : c.holey) {
      near_hole += (p.cast<double>() - centre).norm() < 0.008;
      near_mirror += (p.cast<double>() - mirror).norm() < 0.008;
    }
    EXPECT_EQ(near_hole, 0);
    EXPECT_GT(near_mirror, 5);
  }
  EXPECT_LT(c.holey.size(), c.ground_truth.size());
  EXPECT_GT(c.holey.size(), 0.7 * c.ground_truth.size());
}

TEST(PaperProtocol, RandomPoseIsRigidAndDeterministic) {
  PaperProtocolConfig config;
  config.random_pose = true;
  config.seed = 5;
  const PaperProtocolCloud a = MakePaperProtocolCloud(config);
  const PaperProtocolCloud b = MakePaperProtocolCloud(config);
  EXPECT_TRUE(a.holey == b.holey);
  const Eigen::Matrix3d R = a.T_cloud_object.linear();
  EXPECT_TRUE((R * R.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-9));
  EXPECT_NEAR(R.determinant(), 1.0, 1e-9);
  config.seed = 6;
  EXPECT_FALSE(MakePaperProtocolCloud(config).T_cloud_object.isApprox(a.T_cloud_object));
}

TEST(PaperProtocol, RejectsBadSizes) {
  PaperProtocolConfig config;
  config.size_m = Eigen::Vector3d(0.1, -0.1, 0.2);
  EXPECT_THROW(MakePaperProtocolCloud(config), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::synth
