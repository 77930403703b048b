// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/claw/claw_mask.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "../allocation_count.hpp"
#include "graspfill/claw/claw_model.hpp"
#include "graspfill/core/raycaster.hpp"

namespace graspfill::claw {
namespace {

constexpr float kWallM = 0.6f;
// Rays at the claw's silhouette graze edges; the mask (rays in G) and the
// reference (rays in C) may disagree there by float rounding.
constexpr int kMaxSilhouetteMismatchPx = 3;

DepthFrame Wall(float depth_m) {
  DepthFrame frame;
  frame.depth_m.assign(static_cast<size_t>(frame.intrinsics.width) * frame.intrinsics.height, depth_m);
  return frame;
}

// Gripper 0.42 m in front of the camera, seen obliquely from the side.
Eigen::Isometry3d SidePose() {
  Eigen::Isometry3d T_C_G = Eigen::Isometry3d::Identity();
  T_C_G.linear() =
      (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(1.4, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  T_C_G.translation() = Eigen::Vector3d(-0.04, 0.01, 0.42);
  return T_C_G;
}

// Reference: the claw z-depth per pixel by one Embree ray per pixel over the
// whole image, with the mesh posed in C (no ROI, no packets).
std::vector<float> BruteForceClawDepth(const TriangleMesh& claw_G, const Eigen::Isometry3d& T_C_G,
                                       const CameraIntrinsics& K) {
  Raycaster raycaster;
  raycaster.AddMesh(claw_G.Transformed(T_C_G));
  raycaster.Commit();
  std::vector<float> depth(static_cast<size_t>(K.width) * K.height, 0.0f);
  for (int v = 0; v < K.height; ++v) {
    for (int u = 0; u < K.width; ++u) {
      const Eigen::Vector3f dir((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      const Eigen::Vector3f unit = dir.normalized();
      const RayHit hit = raycaster.Cast(Eigen::Vector3f::Zero(), unit);
      if (hit.hit()) depth[v * K.width + u] = hit.t * unit.z();
    }
  }
  return depth;
}

// Square dilation by `d` pixels of a 0/1 image (reference, O(n d^2)).
std::vector<uint8_t> Dilate(const std::vector<uint8_t>& in, int w, int h, int d) {
  std::vector<uint8_t> out(in.size(), 0);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      for (int dv = -d; dv <= d && !out[v * w + u]; ++dv) {
        for (int du = -d; du <= d; ++du) {
          const int uu = u + du, vv = v + dv;
          if (uu >= 0 && vv >= 0 && uu < w && vv < h && in[vv * w + uu]) {
            out[v * w + u] = 1;
            break;
          }
        }
      }
    }
  }
  return out;
}

int CountMismatches(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  int n = 0;
  for (size_t i = 0; i < a.size(); ++i) n += a[i] != b[i];
  return n;
}

std::vector<uint8_t> ZeroPixels(const DepthFrame& frame) {
  std::vector<uint8_t> zero(frame.depth_m.size());
  for (size_t i = 0; i < zero.size(); ++i) zero[i] = frame.depth_m[i] == 0.0f;
  return zero;
}

class ClawMaskTest : public ::testing::TestWithParam<ClawMaskMethod> {
 protected:
  ClawMaskConfig Config(int dilation_px) const {
    ClawMaskConfig config;
    config.dilation_px = dilation_px;
    config.method = GetParam();
    return config;
  }
  const TriangleMesh claw_G_ = ClawModel::ThreeFinger().Posed(0.035);
};

TEST_P(ClawMaskTest, MatchesBruteForceOnWall) {
  const Eigen::Isometry3d T_C_G = SidePose();
  DepthFrame frame = Wall(kWallM);
  const CameraIntrinsics& K = frame.intrinsics;
  const std::vector<float> ref_depth = BruteForceClawDepth(claw_G_, T_C_G, K);
  std::vector<uint8_t> ref_hit(ref_depth.size());
  int num_hits = 0;
  for (size_t i = 0; i < ref_depth.size(); ++i) {
    ref_hit[i] = ref_depth[i] > 0.0f;
    num_hits += ref_hit[i];
  }
  ASSERT_GT(num_hits, 2000);  // the claw covers a good part of the image

  ClawMask mask(Config(0));
  mask.SetClaw(claw_G_);
  const int removed = mask.Apply(T_C_G, &frame);
  EXPECT_LE(CountMismatches(ZeroPixels(frame), ref_hit), kMaxSilhouetteMismatchPx);
  EXPECT_NEAR(removed, num_hits, kMaxSilhouetteMismatchPx);
  int compared = 0;
  for (size_t i = 0; i < ref_depth.size(); ++i) {
    if (ref_depth[i] > 0.0f && mask.claw_depth_m()[i] > 0.0f) {
      EXPECT_NEAR(mask.claw_depth_m()[i], ref_depth[i], 1e-4) << i;
      ++compared;
    }
  }
  EXPECT_GT(compared, num_hits - kMaxSilhouetteMismatchPx);
}

TEST_P(ClawMaskTest, DilationMatchesReference) {
  const Eigen::Isometry3d T_C_G = SidePose();
  DepthFrame frame = Wall(kWallM);
  const CameraIntrinsics& K = frame.intrinsics;
  const std::vector<float> ref_depth = BruteForceClawDepth(claw_G_, T_C_G, K);
  std::vector<uint8_t> ref_hit(ref_depth.size());
  for (size_t i = 0; i < ref_depth.size(); ++i) ref_hit[i] = ref_depth[i] > 0;
  for (int d : {1, 2, 4}) {
    DepthFrame f = frame;
    ClawMask mask(Config(d));
    mask.SetClaw(claw_G_);
    mask.Apply(T_C_G, &f);
    // Dilating a mismatched silhouette pixel moves a few more pixels.
    EXPECT_LE(CountMismatches(ZeroPixels(f), Dilate(ref_hit, K.width, K.height, d)),
              kMaxSilhouetteMismatchPx * (2 * d + 1))
        << "dilation " << d;
  }
}

TEST_P(ClawMaskTest, CentroidPixelsAreRemoved) {
  // Independent of ray casting: every claw triangle's centroid that projects
  // into the image lies on the claw, so its pixel must go (one pixel of
  // dilation covers the rounding of the projection).
  const Eigen::Isometry3d T_C_G = SidePose();
  DepthFrame frame = Wall(kWallM);
  const CameraIntrinsics& K = frame.intrinsics;
  ClawMask mask(Config(1));
  mask.SetClaw(claw_G_);
  mask.Apply(T_C_G, &frame);
  int checked = 0;
  for (const Eigen::Vector3i& t : claw_G_.triangles) {
    const Eigen::Vector3d c_G =
        ((claw_G_.vertices[t[0]] + claw_G_.vertices[t[1]] + claw_G_.vertices[t[2]]) / 3.0f).cast<double>();
    const Eigen::Vector3d c_C = T_C_G * c_G;
    const int u = static_cast<int>(std::lround(K.fx * c_C.x() / c_C.z() + K.cx));
    const int v = static_cast<int>(std::lround(K.fy * c_C.y() / c_C.z() + K.cy));
    if (u < 0 || v < 0 || u >= K.width || v >= K.height) continue;
    EXPECT_EQ(frame.at(u, v), 0.0f) << "centroid pixel " << u << "," << v;
    ++checked;
  }
  EXPECT_GT(checked, 50);
}

TEST_P(ClawMaskTest, KeepsObjectBesideAndInFront) {
  const Eigen::Isometry3d T_C_G = SidePose();
  const DepthFrame wall = Wall(kWallM);
  const CameraIntrinsics& K = wall.intrinsics;
  const int d = 2;
  ClawMask mask(Config(d));
  mask.SetClaw(claw_G_);
  DepthFrame probe = wall;
  mask.Apply(T_C_G, &probe);
  const std::vector<float> claw_z = mask.claw_depth_m();

  // Object surface: in front of the claw by 2 cm where the claw is, 0.5 m
  // elsewhere (beside the claw).
  DepthFrame frame = wall;
  for (size_t i = 0; i < claw_z.size(); ++i) {
    frame.depth_m[i] = claw_z[i] > 0 ? claw_z[i] - 0.02f : 0.5f;
  }
  const DepthFrame before = frame;
  EXPECT_EQ(mask.Apply(T_C_G, &frame), 0);
  EXPECT_EQ(frame.depth_m, before.depth_m);

  // Only the claw's own pixels are cut when the object is beside it: kept
  // beyond the dilation, cut within it.
  std::vector<uint8_t> on_claw(claw_z.size(), 0);
  for (size_t i = 0; i < claw_z.size(); ++i) on_claw[i] = claw_z[i] > 0;
  const std::vector<uint8_t> near_claw = Dilate(on_claw, K.width, K.height, d);
  frame = wall;
  for (size_t i = 0; i < claw_z.size(); ++i) {
    if (!on_claw[i]) frame.depth_m[i] = 0.5f;
  }
  mask.Apply(T_C_G, &frame);
  int kept_beside = 0;
  for (size_t i = 0; i < claw_z.size(); ++i) {
    if (near_claw[i]) {
      EXPECT_EQ(frame.depth_m[i], 0.0f) << i;
    } else {
      ASSERT_EQ(frame.depth_m[i], 0.5f) << "beside the claw " << i;
      ++kept_beside;
    }
  }
  EXPECT_GT(kept_beside, K.width * K.height / 2);

  // Dropouts on the claw stay dropouts and are not counted as removed.
  ClawMask undilated(Config(0));
  undilated.SetClaw(claw_G_);
  frame = wall;
  for (size_t i = 0; i < claw_z.size(); ++i) {
    if (on_claw[i]) frame.depth_m[i] = 0.0f;
  }
  EXPECT_EQ(undilated.Apply(T_C_G, &frame), 0);

  // Within the margin the claw wins: an object 2 mm in front is cut.
  ClawMaskConfig config = Config(0);
  config.front_margin_m = 0.004;
  ClawMask tight(config);
  tight.SetClaw(claw_G_);
  DepthFrame close = wall;
  for (size_t i = 0; i < claw_z.size(); ++i) {
    if (claw_z[i] > 0) close.depth_m[i] = claw_z[i] - 0.002f;
  }
  EXPECT_GT(tight.Apply(T_C_G, &close), 1000);
}

TEST_P(ClawMaskTest, MovingClawClearsOldDepths) {
  ClawMask mask(Config(0));
  mask.SetClaw(claw_G_);
  DepthFrame frame = Wall(kWallM);
  mask.Apply(SidePose(), &frame);
  Eigen::Isometry3d moved = SidePose();
  moved.translation().x() += 0.15;
  frame = Wall(kWallM);
  const float* buffer = mask.claw_depth_m().data();
  mask.Apply(moved, &frame);
  EXPECT_EQ(mask.claw_depth_m().data(), buffer);  // reused, not reallocated
  const std::vector<float> ref = BruteForceClawDepth(claw_G_, moved, frame.intrinsics);
  int mismatches = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    mismatches += (ref[i] > 0) != (mask.claw_depth_m()[i] > 0);
  }
  EXPECT_LE(mismatches, kMaxSilhouetteMismatchPx);
}

TEST_P(ClawMaskTest, NoAllocationAfterFirstFrame) {
  ClawMask mask(Config(2));
  mask.SetClaw(claw_G_);
  DepthFrame frame = Wall(kWallM);
  mask.Apply(SidePose(), &frame);  // sizes the buffers
  Eigen::Isometry3d T_C_G = SidePose();
  const long before = testing::Allocations();
  for (int k = 0; k < 5; ++k) {
    T_C_G.translation().x() += 0.02;
    mask.Apply(T_C_G, &frame);
  }
  // Camera inside the claw's box: the fallback path must not allocate
  // either.
  T_C_G = Eigen::Isometry3d::Identity();
  T_C_G.translation() = Eigen::Vector3d(0, 0, -0.03);
  mask.Apply(T_C_G, &frame);
  EXPECT_EQ(testing::Allocations() - before, 0);
}

TEST_P(ClawMaskTest, ClawAroundAndBehindCamera) {
  ClawMask mask(Config(0));
  mask.SetClaw(claw_G_);
  // Camera inside the claw's box, looking along the approach: some box
  // corners are behind it, so the whole image is cast.
  Eigen::Isometry3d T_C_G = Eigen::Isometry3d::Identity();
  T_C_G.translation() = Eigen::Vector3d(0, 0, -0.03);
  DepthFrame frame = Wall(kWallM);
  const std::vector<float> ref = BruteForceClawDepth(claw_G_, T_C_G, frame.intrinsics);
  std::vector<uint8_t> ref_hit(ref.size());
  for (size_t i = 0; i < ref.size(); ++i) ref_hit[i] = ref[i] > 0;
  mask.Apply(T_C_G, &frame);
  EXPECT_LE(CountMismatches(ZeroPixels(frame), ref_hit), kMaxSilhouetteMismatchPx);
  // Wholly behind the camera: nothing to cut.
  T_C_G.translation() = Eigen::Vector3d(0, 0, -0.5);
  frame = Wall(kWallM);
  EXPECT_EQ(mask.Apply(T_C_G, &frame), 0);
  // Off to the side of the image: nothing either.
  T_C_G.translation() = Eigen::Vector3d(3.0, 0, 0.5);
  EXPECT_EQ(mask.Apply(T_C_G, &frame), 0);
}

TEST_P(ClawMaskTest, RejectsBadFrames) {
  ClawMask mask(Config(0));
  mask.SetClaw(claw_G_);
  DepthFrame frame = Wall(kWallM);
  frame.depth_m.pop_back();
  EXPECT_EQ(mask.Apply(SidePose(), &frame), -1);
  EXPECT_EQ(mask.Apply(SidePose(), nullptr), -1);
  ClawMask no_claw(Config(0));
  DepthFrame wall = Wall(kWallM);
  EXPECT_EQ(no_claw.Apply(SidePose(), &wall), 0);
}

std::string MethodName(ClawMaskMethod method) {
  switch (method) {
    case ClawMaskMethod::kRaster:
      return "Raster";
    case ClawMaskMethod::kRayPackets:
      return "RayPackets";
    case ClawMaskMethod::kRays:
      return "Rays";
  }
  return "Unknown";
}

INSTANTIATE_TEST_SUITE_P(Methods, ClawMaskTest,
                         ::testing::Values(ClawMaskMethod::kRaster, ClawMaskMethod::kRayPackets,
                                           ClawMaskMethod::kRays),
                         [](const ::testing::TestParamInfo<ClawMaskMethod>& info) {
                           return MethodName(info.param);
                         });

TEST(ClawMaskConfigTest, Defaults) {
  const ClawMaskConfig config;
  EXPECT_DOUBLE_EQ(config.front_margin_m, 0.004);
  EXPECT_EQ(config.dilation_px, 2);
  EXPECT_EQ(config.roi_margin_px, 1);
  EXPECT_EQ(config.method, ClawMaskMethod::kRayPackets);
  ClawMaskConfig bad;
  bad.dilation_px = -1;
  EXPECT_THROW(ClawMask{bad}, std::invalid_argument);
}

// Not an assertion: prints the mask's time per frame for each method.
TEST(ClawMaskTiming, PrintTimePerFrame) {
  const TriangleMesh claw_G = ClawModel::ThreeFinger().Posed(0.035);
  Eigen::Isometry3d T_C_G = SidePose();
  T_C_G.translation().z() = 0.6;  // the paper's working distance
  const DepthFrame wall = Wall(0.8f);
  for (ClawMaskMethod method :
       {ClawMaskMethod::kRays, ClawMaskMethod::kRayPackets, ClawMaskMethod::kRaster}) {
    ClawMaskConfig config;
    config.method = method;
    ClawMask mask(config);
    mask.SetClaw(claw_G);
    DepthFrame frame = wall;
    mask.Apply(T_C_G, &frame);  // first frame sizes the buffers
    constexpr int kFrames = 200;
    std::vector<double> ms;
    int removed = 0;
    for (int k = 0; k < kFrames; ++k) {
      frame.depth_m = wall.depth_m;
      const auto t0 = std::chrono::steady_clock::now();
      removed = mask.Apply(T_C_G, &frame);
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    // The median resists other processes sharing the machine.
    std::nth_element(ms.begin(), ms.begin() + kFrames / 2, ms.end());
    std::printf("claw mask %-10s: %.3f ms/frame median (%d px removed, %d rays)\n",
                MethodName(method).c_str(), ms[kFrames / 2], removed, mask.last_ray_count());
  }
}

}  // namespace
}  // namespace graspfill::claw
