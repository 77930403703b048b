// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/fusion/workspace_crop.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace graspfill::fusion {
namespace {

// Camera 0.5 m in front of G, looking along G's x axis (C's z = G's +x).
Eigen::Isometry3d SideCamera() {
  Eigen::Isometry3d T_G_C = Eigen::Isometry3d::Identity();
  T_G_C.linear().col(0) = Eigen::Vector3d(0, 1, 0);  // x_C
  T_G_C.linear().col(1) = Eigen::Vector3d(0, 0, 1);  // y_C (down = +z_G)
  T_G_C.linear().col(2) = Eigen::Vector3d(1, 0, 0);  // z_C
  T_G_C.translation() = Eigen::Vector3d(-0.5, 0, 0.1);
  return T_G_C.inverse();
}

// A 10 cm cube, 5 to 15 cm along G's z.
WorkspaceBox SmallBox() {
  WorkspaceBox box;
  box.min_G = Eigen::Vector3d(-0.05, -0.05, 0.05);
  box.max_G = Eigen::Vector3d(0.05, 0.05, 0.15);
  return box;
}

TEST(WorkspaceCrop, KeepsExactlyThePixelsInsideTheBox) {
  const WorkspaceBox box = SmallBox();
  const Eigen::Isometry3d T_C_G = SideCamera();
  DepthFrame f;
  // A wall through G's origin plane x = 0 (0.5 m away) and a far background.
  f.depth_m.assign(640 * 480, 0.5f);
  for (int u = 0; u < 640; ++u) f.depth_m[10 * 640 + u] = 2.0f;
  PixelRect roi;
  const int kept = CropToWorkspace(box, T_C_G, &f, &roi);
  // The wall inside the box is a 10 x 10 cm square at 0.5 m: 105 x 105 px.
  const double side_px = 0.10 * 525.0 / 0.5;
  EXPECT_NEAR(kept, side_px * side_px, 4 * side_px);
  int nonzero = 0;
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      if (f.depth_m[v * 640 + u] == 0.0f) continue;
      ++nonzero;
      EXPECT_TRUE(u >= roi.u0 && u < roi.u1 && v >= roi.v0 && v < roi.v1);
      const Eigen::Vector3d p_C((u - 319.5) / 525.0 * 0.5, (v - 239.5) / 525.0 * 0.5, 0.5);
      // float arithmetic in the crop: allow 1 um at the faces
      WorkspaceBox grown = box;
      grown.min_G.array() -= 1e-6;
      grown.max_G.array() += 1e-6;
      EXPECT_TRUE(grown.Contains(T_C_G.inverse() * p_C));
    }
  }
  EXPECT_EQ(nonzero, kept);
  EXPECT_EQ(f.depth_m[10 * 640 + 320], 0.0f);  // background removed
}

// Cropped into another frame: the same depths, count and rectangle as in
// place, and the source untouched; a reused target of another size is
// resized.
TEST(WorkspaceCrop, IntoAnotherFrameIsTheCropInPlace) {
  const WorkspaceBox box = SmallBox();
  const Eigen::Isometry3d T_C_G = SideCamera();
  DepthFrame source;
  source.utime = 42;
  source.depth_m.resize(640 * 480);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      // A wall tilted through the box, holes and a NaN among it.
      float z = 0.45f + 0.0004f * static_cast<float>(u % 300) + 0.0002f * static_cast<float>(v % 200);
      if ((u * 7 + v * 13) % 29 == 0) z = 0.0f;
      source.depth_m[static_cast<size_t>(v) * 640 + u] = z;
    }
  }
  source.depth_m[300 * 640 + 320] = std::nanf("");
  DepthFrame in_place = source;
  PixelRect roi_in_place;
  const int kept_in_place = CropToWorkspace(box, T_C_G, &in_place, &roi_in_place);
  ASSERT_GT(kept_in_place, 1000);
  DepthFrame out;
  out.depth_m.assign(17, 3.0f);
  PixelRect roi;
  const DepthFrame copy = source;
  EXPECT_EQ(CropToWorkspace(box, T_C_G, source, &out, &roi), kept_in_place);
  EXPECT_EQ(out.utime, 42);
  EXPECT_EQ(roi.u0, roi_in_place.u0);
  EXPECT_EQ(roi.v1, roi_in_place.v1);
  ASSERT_EQ(out.depth_m.size(), in_place.depth_m.size());
  EXPECT_EQ(std::memcmp(out.depth_m.data(), in_place.depth_m.data(), sizeof(float) * out.depth_m.size()), 0);
  EXPECT_EQ(std::memcmp(source.depth_m.data(), copy.depth_m.data(), sizeof(float) * source.depth_m.size()),
            0);
}

TEST(WorkspaceCrop, BoxBehindCameraUsesFullImageAndNaNIsCleared) {
  WorkspaceBox box;  // default box, camera inside it
  DepthFrame f;
  f.depth_m.assign(640 * 480, 0.0f);
  f.depth_m[5] = std::nanf("");
  const PixelRect r = ProjectBox(box, Eigen::Isometry3d::Identity(), f.intrinsics);
  EXPECT_EQ(r.area(), 640 * 480);
  CropToWorkspace(box, Eigen::Isometry3d::Identity(), &f);
  EXPECT_EQ(f.depth_m[5], 0.0f);
}

// Issue 12: fx = 1e300 or cx = 1e308 overflowed double -> int (UBSan); in
// practice the rectangle came out empty and every pixel was cropped.
TEST(WorkspaceCrop, ExtremeIntrinsicsGiveAConservativeRectangle) {
  const WorkspaceBox box = SmallBox();
  CameraIntrinsics K;
  K.fx = K.fy = 1e300;  // the box straddles the optical axis: +-1e299 px
  PixelRect r = ProjectBox(box, SideCamera(), K);
  EXPECT_EQ(r.u0, 0);
  EXPECT_EQ(r.u1, K.width);
  K = CameraIntrinsics{};
  K.cx = 1e308;  // everything far right of the image
  r = ProjectBox(box, SideCamera(), K);
  EXPECT_EQ(r.u0, K.width);
  EXPECT_EQ(r.u1, K.width);
  K.cx = -1e308;  // far left
  r = ProjectBox(box, SideCamera(), K);
  EXPECT_EQ(r.u0, 0);
  EXPECT_EQ(r.u1, 0);
}

// A depth that does not match its size is refused, not read past its end.
TEST(WorkspaceCrop, RefusesADepthOfAnotherSize) {
  DepthFrame f;
  f.depth_m.assign(640 * 479, 0.5f);
  EXPECT_THROW(CropToWorkspace(SmallBox(), SideCamera(), &f), std::invalid_argument);
  DepthFrame out;
  EXPECT_THROW(CropToWorkspace(SmallBox(), SideCamera(), f, &out), std::invalid_argument);
  f.depth_m.assign(640 * 480, 0.5f);
  f.intrinsics.width = 0;
  EXPECT_THROW(CropToWorkspace(SmallBox(), SideCamera(), f, &out), std::invalid_argument);
}

TEST(WorkspaceCrop, ValidateRejectsInvertedBox) {
  WorkspaceBox box;
  box.max_G.z() = box.min_G.z() - 0.01;
  EXPECT_THROW(box.Validate(), std::invalid_argument);
  EXPECT_NO_THROW(WorkspaceBox{}.Validate());
}

}  // namespace
}  // namespace graspfill::fusion
