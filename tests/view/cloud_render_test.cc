// SPDX-License-Identifier: BSD-3-Clause
// One view of a cloud: the framing that holds every cloud of a picture,
// and points the framing does not hold.
#include "graspfill/view/cloud_render.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace graspfill::view {
namespace {

TEST(CloudRenderTest, FramingHoldsEveryCloud) {
  ObjectCloud a, b;
  a.points_G = {{0.0f, 0.0f, 0.0f}, {0.1f, 0.0f, 0.0f}};
  b.points_G = {{0.0f, 0.2f, 0.0f}, {std::nanf(""), 5.0f, 5.0f}};  // the NaN point is ignored
  const Framing f = FrameClouds({&a, &b});
  EXPECT_TRUE(f.center_G.isApprox(Eigen::Vector3d(0.05, 0.1, 0.0), 1e-6));
  EXPECT_NEAR(f.radius_m, 0.5 * std::hypot(0.1, 0.2), 1e-6);
  // No point at all: a default framing, not a zero radius.
  const ObjectCloud empty;
  EXPECT_GT(FrameClouds({&empty}).radius_m, 0.0);
}

// A framing that misses the cloud (far away, absurd numbers) draws nothing
// and writes nowhere outside the image.
TEST(CloudRenderTest, PointsOutsideTheFramingAreSkipped) {
  ObjectCloud cloud;
  cloud.points_G = {{1e30f, -1e30f, 0.0f}, {5.0f, 5.0f, 5.0f}, {-3e9f, 0.0f, 1e9f}};
  cloud.provenance.assign(cloud.size(), Provenance::kSurface);
  RgbImage image;
  image.width = 100;
  image.height = 100;
  image.rgb.assign(100 * 100 * 3, 255);
  Framing framing;
  framing.radius_m = 0.01;
  RenderView(cloud, framing, ViewAngle{}, 10, 10, 80, &image);
  EXPECT_EQ(image.rgb, std::vector<uint8_t>(100 * 100 * 3, 255));
  // The same cloud framed: drawn.
  RenderView(cloud, FrameClouds({&cloud}), ViewAngle{}, 10, 10, 80, &image);
  EXPECT_NE(image.rgb, std::vector<uint8_t>(100 * 100 * 3, 255));
}

}  // namespace
}  // namespace graspfill::view
