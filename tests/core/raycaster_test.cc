// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/core/raycaster.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace graspfill {
namespace {

// Two triangles forming the square |x|,|y| <= 1 in the plane z = depth.
TriangleMesh Square(float depth) {
  TriangleMesh m;
  m.vertices = {{-1, -1, depth}, {1, -1, depth}, {1, 1, depth}, {-1, 1, depth}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

TEST(Raycaster, HitsNearestSurfaceAtAnalyticDistance) {
  Raycaster rc;
  const unsigned far_id = rc.AddMesh(Square(2.0f));
  const unsigned near_id = rc.AddMesh(Square(0.5f));
  rc.Commit();
  const Eigen::Vector3f dir = Eigen::Vector3f(0.3f, 0.2f, 1.0f).normalized();
  const RayHit hit = rc.Cast(Eigen::Vector3f::Zero(), dir);
  ASSERT_TRUE(hit.hit());
  EXPECT_EQ(hit.geom_id, near_id);
  EXPECT_NE(hit.geom_id, far_id);
  EXPECT_NEAR(hit.t, 0.5f / dir.z(), 1e-5f);
  // Starting past the near square, the far one is hit.
  EXPECT_NEAR(rc.Cast(Eigen::Vector3f::Zero(), dir, 0.6f).t, 2.0f / dir.z(), 1e-5f);
  EXPECT_FALSE(rc.Cast(Eigen::Vector3f::Zero(), -dir).hit());
  EXPECT_TRUE(rc.Occluded(Eigen::Vector3f::Zero(), dir, 0.0f, 1.0f));
  EXPECT_FALSE(rc.Occluded(Eigen::Vector3f::Zero(), dir, 0.0f, 0.4f));
}

TEST(Raycaster, PacketMatchesSingleRays) {
  Raycaster rc;
  rc.AddMesh(Square(1.0f));
  rc.Commit();
  float dirs[16][3];
  for (int i = 0; i < 16; ++i) {
    const Eigen::Vector3f d = Eigen::Vector3f(-1.5f + 0.2f * i, 0.1f, 1.0f).normalized();
    dirs[i][0] = d.x();
    dirs[i][1] = d.y();
    dirs[i][2] = d.z();
  }
  float t[16];
  rc.Cast16(Eigen::Vector3f::Zero(), dirs, 13, t);
  for (int i = 0; i < 13; ++i) {
    const Eigen::Vector3f d(dirs[i][0], dirs[i][1], dirs[i][2]);
    const RayHit single = rc.Cast(Eigen::Vector3f::Zero(), d);
    if (single.hit())
      EXPECT_NEAR(t[i], single.t, 1e-5f) << i;
    else
      EXPECT_TRUE(std::isinf(t[i])) << i;
  }
}

TEST(Raycaster, RejectsOutOfRangeIndices) {
  Raycaster rc;
  TriangleMesh bad = Square(1.0f);
  bad.triangles.push_back({0, 1, 7});
  EXPECT_THROW(rc.AddMesh(bad), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill
