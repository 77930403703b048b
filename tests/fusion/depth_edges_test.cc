// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/fusion/depth_edges.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace graspfill::fusion {
namespace {

constexpr int kW = 640, kH = 480;

DepthFrame Blank() {
  DepthFrame f;
  f.depth_m.assign(static_cast<size_t>(kW) * kH, 0.0f);
  return f;  // default intrinsics: VGA, f = 525 px
}

const PixelRect kWhole{0, 0, kW, kH};

// A plane through (0, 0, 0.5 m) tilted about the camera's y axis so that
// the central ray meets it at `incidence_deg`; each pixel's ray depth.
DepthFrame TiltedPlane(double incidence_deg) {
  DepthFrame f = Blank();
  const double k = std::tan(incidence_deg * M_PI / 180.0);
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) {
      const double x_over_z = (u - f.intrinsics.cx) / f.intrinsics.fx;
      const double denominator = 1.0 - k * x_over_z;
      if (denominator <= 0.0) continue;
      const double z = 0.5 / denominator;
      if (z > 0.3 && z < 0.9) f.depth_m[static_cast<size_t>(v) * kW + u] = static_cast<float>(z);
    }
  }
  return f;
}

int Returns(const DepthFrame& f) {
  int n = 0;
  for (float z : f.depth_m) n += z > 0.0f;
  return n;
}

TEST(DepthEdges, ASurfaceTheSensorSeesIsKeptWhole) {
  for (double incidence_deg : {0.0, 45.0, 70.0, 75.0}) {
    DepthFrame f = TiltedPlane(incidence_deg);
    const int before = Returns(f);
    ASSERT_GT(before, 10000) << incidence_deg;
    std::vector<uint8_t> marks;
    EXPECT_EQ(RejectDepthEdges(kWhole, &f, &marks), 0) << incidence_deg;
    EXPECT_EQ(Returns(f), before);
  }
}

TEST(DepthEdges, ASurfaceSteeperThanTheSensorSeesIsAnEdge) {
  // At 88 deg neighbours lie 15-45 mm apart in depth: no surface the
  // sensor returns, the pixels of a depth edge.
  DepthFrame f = TiltedPlane(88.0);
  const int before = Returns(f);
  ASSERT_GT(before, 1000);
  std::vector<uint8_t> marks;
  EXPECT_EQ(RejectDepthEdges(kWhole, &f, &marks), before);
  EXPECT_EQ(Returns(f), 0);
}

// An object at 0.5 m in the left half, the background at 1.5 m, and a
// column of flying pixels between them at 1.0 m.
TEST(DepthEdges, FlyingPixelsAndBothSidesOfTheirJumpsGo) {
  DepthFrame f = Blank();
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) {
      f.depth_m[static_cast<size_t>(v) * kW + u] = u < 320 ? 0.5f : u == 320 ? 1.0f : 1.5f;
    }
  }
  std::vector<uint8_t> marks;
  EXPECT_EQ(RejectDepthEdges(kWhole, &f, &marks), 3 * kH);
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) {
      const bool edge = u >= 319 && u <= 321;
      EXPECT_EQ(f.depth_m[static_cast<size_t>(v) * kW + u] == 0.0f, edge) << u << "," << v;
    }
  }
}

TEST(DepthEdges, NoReturnIsNoEdgeAndOutsideTheRectangleNothingChanges) {
  DepthFrame f = TiltedPlane(0.0);
  // A hole without returns in the plane: its rim is no edge.
  for (int v = 200; v < 260; ++v) {
    for (int u = 300; u < 340; ++u) f.depth_m[static_cast<size_t>(v) * kW + u] = 0.0f;
  }
  // A jump outside the rectangle given: not read, not changed.
  for (int v = 0; v < kH; ++v) f.depth_m[static_cast<size_t>(v) * kW + 600] = 2.0f;
  const int before = Returns(f);
  std::vector<uint8_t> marks;
  EXPECT_EQ(RejectDepthEdges(PixelRect{0, 0, 500, kH}, &f, &marks), 0);
  EXPECT_EQ(Returns(f), before);
  // The whole frame: the jump's column and its two neighbours go.
  EXPECT_EQ(RejectDepthEdges(kWhole, &f, &marks), 3 * kH);
}

TEST(DepthEdges, ABufferOfTheWrongSizeIsRefused) {
  DepthFrame f = Blank();
  f.depth_m.resize(100);
  std::vector<uint8_t> marks;
  EXPECT_THROW(RejectDepthEdges(kWhole, &f, &marks), std::invalid_argument);
}

TEST(DepthEdges, TheScratchIsReused) {
  DepthFrame f = TiltedPlane(88.0);
  std::vector<uint8_t> marks;
  RejectDepthEdges(kWhole, &f, &marks);
  const uint8_t* data = marks.data();
  DepthFrame g = TiltedPlane(88.0);
  EXPECT_GT(RejectDepthEdges(kWhole, &g, &marks), 0);
  EXPECT_EQ(marks.data(), data);  // no new allocation for a frame of the same size
}

}  // namespace
}  // namespace graspfill::fusion
