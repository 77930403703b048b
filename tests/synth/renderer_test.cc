// SPDX-License-Identifier: BSD-3-Clause
#include "synth/renderer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "graspfill/mesh/mesh_geometry.hpp"
#include "synth/shapes.hpp"

namespace graspfill::synth {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Embree's float hit distance on a plane: a few ulp at 1 m.
constexpr double kPlaneTolM = 1e-5;
// A 256-segment sphere is inscribed in the true one: < 10 um radially,
// < 25 um along rays at least 26 deg off grazing.
constexpr double kSphereTolM = 5e-5;

Eigen::Vector3d RayC(const CameraIntrinsics& k, int u, int v) {
  return Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
}

TEST(DepthRendererTest, WallIsAnalytic) {
  DepthRenderer renderer(CameraIntrinsics{}, 1.3);
  renderer.Commit();
  IdealDepthImage image;
  renderer.Render(Eigen::Isometry3d::Identity(), &image);
  const CameraIntrinsics& k = image.intrinsics;
  ASSERT_EQ(image.depth_m.size(), static_cast<size_t>(k.width * k.height));
  for (int v = 0; v < k.height; v += 7) {
    for (int u = 0; u < k.width; u += 7) {
      const size_t i = static_cast<size_t>(v) * k.width + u;
      EXPECT_FLOAT_EQ(image.depth_m[i], 1.3f);
      EXPECT_NEAR(image.cos_incidence[i], 1.0 / RayC(k, u, v).norm(), 1e-6);
      EXPECT_EQ(image.label[i], SurfaceLabel::kBackground);
    }
  }
}

TEST(DepthRendererTest, BoxFaceIsAnalyticPlane) {
  // A box whose -z face is the plane z = 0.6 in C, with G = C.
  TriangleMesh box = MakeShape(Shape::kCuboid, Eigen::Vector3d(0.2, 0.2, 0.1));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().z() = 0.6;
  DepthRenderer renderer(CameraIntrinsics{}, 0.0);
  renderer.AddMesh(box.Transformed(T), SurfaceLabel::kObject);
  renderer.Commit();
  IdealDepthImage image;
  renderer.Render(Eigen::Isometry3d::Identity(), &image);
  const CameraIntrinsics& k = image.intrinsics;
  int checked = 0;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Eigen::Vector3d hit = 0.6 * RayC(k, u, v);
      const size_t i = static_cast<size_t>(v) * k.width + u;
      if (std::abs(hit.x()) < 0.098 && std::abs(hit.y()) < 0.098) {
        ASSERT_NEAR(image.depth_m[i], 0.6, kPlaneTolM) << u << "," << v;
        EXPECT_NEAR(image.cos_incidence[i], 1.0 / RayC(k, u, v).norm(), 1e-5);
        EXPECT_EQ(image.label[i], SurfaceLabel::kObject);
        ++checked;
      } else if (std::abs(hit.x()) > 0.102 || std::abs(hit.y()) > 0.102) {
        EXPECT_EQ(image.depth_m[i], 0.0f) << "no wall: nothing beyond the box";
        EXPECT_EQ(image.label[i], SurfaceLabel::kNone);
      }
    }
  }
  EXPECT_GT(checked, 10000);
}

// The projector, 75 mm along +x of the camera, casts a plate's shadow on
// a wall of boxes behind it: a band on the plate's -u side, as wide as the
// parallax between the two depths, f b (1 / z_plate - 1 / z_back); the
// plate itself is lit. Without the option nothing is marked.
TEST(DepthRendererTest, ProjectorShadowIsTheParallaxBand) {
  const double z_plate = 0.5, z_back = 0.8;
  Eigen::Isometry3d at_plate = Eigen::Isometry3d::Identity(), at_back = Eigen::Isometry3d::Identity();
  at_plate.translation().z() = z_plate;
  at_back.translation().z() = z_back;
  const TriangleMesh plate =
      MakeShape(Shape::kCuboid, Eigen::Vector3d(0.04, 0.04, 0.002)).Transformed(at_plate);
  const TriangleMesh back = MakeShape(Shape::kCuboid, Eigen::Vector3d(0.4, 0.4, 0.05)).Transformed(at_back);
  SensorModelConfig sensor;
  for (const bool shadow : {false, true}) {
    DepthRenderer renderer(CameraIntrinsics{}, 0.0);
    renderer.AddMesh(plate, SurfaceLabel::kClaw);
    renderer.AddMesh(back, SurfaceLabel::kObject);
    renderer.Commit();
    sensor.projector_shadow = shadow;
    renderer.SetUnlit(sensor, 1);
    IdealDepthImage image;
    renderer.Render(Eigen::Isometry3d::Identity(), &image);
    if (!shadow) {
      EXPECT_TRUE(image.unlit.empty());
      continue;
    }
    const CameraIntrinsics& k = image.intrinsics;
    ASSERT_EQ(image.unlit.size(), image.depth_m.size());
    const int v = static_cast<int>(k.cy);
    int band = 0, plate_left = k.width, lit_plate = 0;
    for (int u = 0; u < k.width; ++u) {
      const size_t i = static_cast<size_t>(v) * k.width + u;
      if (image.label[i] == SurfaceLabel::kClaw) {
        plate_left = std::min(plate_left, u);
        lit_plate += image.unlit[i] == kLit;
      }
    }
    for (int u = 0; u < k.width; ++u) {
      const size_t i = static_cast<size_t>(v) * k.width + u;
      if (image.label[i] != SurfaceLabel::kObject || !(image.unlit[i] & kProjectorShadow)) continue;
      ++band;
      EXPECT_LT(u, plate_left) << "the shadow lies on the plate's -u side";
    }
    const double expected = k.fx * sensor.baseline_m * (1.0 / (z_plate + 0.002) - 1.0 / z_back);
    std::printf("shadow band %d px, parallax %.1f px\n", band, expected);
    EXPECT_NEAR(band, expected, 2.0);
    EXPECT_GT(lit_plate, 30);
  }
}

// Dark patches cover about the share asked of the object's pixels, none
// of the claw's, and the sensor returns nothing there.
TEST(DepthRendererTest, DarkPatchesCoverTheirShareOfTheObject) {
  Eigen::Isometry3d at = Eigen::Isometry3d::Identity();
  at.translation().z() = 0.6;
  DepthRenderer renderer(CameraIntrinsics{}, 0.0);
  renderer.AddMesh(MakeShape(Shape::kCuboid, Eigen::Vector3d(0.2, 0.2, 0.1)).Transformed(at),
                   SurfaceLabel::kObject);
  renderer.Commit();
  SensorModelConfig sensor = SensorModelConfig::Ideal();
  sensor.dark_patch_share = 0.2;
  sensor.dark_patch_size_m = 0.01;
  renderer.SetUnlit(sensor, 7);
  IdealDepthImage image;
  renderer.Render(Eigen::Isometry3d::Identity(), &image);
  const DepthFrame frame = ApplySensorModel(sensor, image, 3, 0);
  int object = 0, dark = 0, dark_returned = 0, lit_lost = 0;
  for (size_t i = 0; i < image.depth_m.size(); ++i) {
    if (image.label[i] != SurfaceLabel::kObject) continue;
    ++object;
    const bool is_dark = image.unlit[i] & kDarkPatch;
    dark += is_dark;
    dark_returned += is_dark && frame.depth_m[i] > 0.0f;
    lit_lost += !is_dark && !(frame.depth_m[i] > 0.0f);
  }
  ASSERT_GT(object, 10000);
  const double share = static_cast<double>(dark) / object;
  std::printf("dark patches: %.3f of the object's pixels (asked 0.2)\n", share);
  EXPECT_NEAR(share, 0.2, 0.07);
  EXPECT_EQ(dark_returned, 0);
  EXPECT_EQ(lit_lost, 0);
}

// Another resolution keeps the field of view: an off-centre box covers
// the same part of the image at 640 x 480 and at 1600 x 1200 (6.25 x the
// pixels), and a 4096 x 4096 image spans the same angles across.
TEST(DepthRendererTest, OtherResolutionsKeepTheFieldOfView) {
  TriangleMesh box = MakeShape(Shape::kCuboid, Eigen::Vector3d(0.1, 0.08, 0.05));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.07, -0.05, 0.5);
  auto box_pixels = [&](const CameraIntrinsics& k) {
    DepthRenderer renderer(k, 0.0);
    renderer.AddMesh(box.Transformed(T), SurfaceLabel::kObject);
    renderer.Commit();
    IdealDepthImage image;
    renderer.Render(Eigen::Isometry3d::Identity(), &image);
    int n = 0;
    for (SurfaceLabel label : image.label) n += label == SurfaceLabel::kObject;
    return n;
  };
  const CameraIntrinsics vga = IntrinsicsAtResolution(640, 480);
  EXPECT_EQ(vga, CameraIntrinsics{});
  const int at_vga = box_pixels(vga);
  const int at_uxga = box_pixels(IntrinsicsAtResolution(1600, 1200));
  ASSERT_GT(at_vga, 5000);
  EXPECT_NEAR(static_cast<double>(at_uxga) / at_vga, 6.25, 0.06);
  const CameraIntrinsics big = IntrinsicsAtResolution(4096, 4096);
  EXPECT_NEAR(big.cx / (big.width - 1), vga.cx / (vga.width - 1), 1e-12);
  EXPECT_NEAR((big.width / big.fx), (vga.width / vga.fx), 1e-12);
  EXPECT_NEAR((big.height / big.fy), (vga.height / vga.fy), 1e-12);
}

TEST(DepthRendererTest, SphereIsAnalyticThroughAPose) {
  const double radius = 0.05;
  // Sphere centred at c_G in G; the camera sees G through a rotated pose.
  const Eigen::Vector3d c_G(0.01, -0.02, 0.03);
  TriangleMesh sphere = MakeShape(Shape::kSphere, Eigen::Vector3d::Constant(2 * radius), 256);
  Eigen::Isometry3d T_G_O = Eigen::Isometry3d::Identity();
  T_G_O.translation() = c_G - Eigen::Vector3d(0, 0, radius);
  Eigen::Isometry3d T_C_G = Eigen::Isometry3d::Identity();
  T_C_G.linear() = (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  T_C_G.translation() = Eigen::Vector3d(0.03, 0.02, 0.7) - T_C_G.linear() * c_G;
  const Eigen::Vector3d c_C = T_C_G * c_G;

  DepthRenderer renderer(CameraIntrinsics{}, 1.5);
  renderer.AddMesh(sphere.Transformed(T_G_O), SurfaceLabel::kObject);
  renderer.Commit();
  IdealDepthImage image;
  renderer.Render(T_C_G, &image);
  const CameraIntrinsics& k = image.intrinsics;
  int checked = 0;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Eigen::Vector3d d = RayC(k, u, v);
      const size_t i = static_cast<size_t>(v) * k.width + u;
      // Distance of the ray (through the origin) from the centre.
      const double miss = d.normalized().cross(c_C).norm();
      if (miss < 0.9 * radius) {
        const double b = d.dot(c_C);
        const double t = (b - std::sqrt(b * b - d.squaredNorm() * (c_C.squaredNorm() - radius * radius))) /
                         d.squaredNorm();
        ASSERT_NEAR(image.depth_m[i], t * d.z(), kSphereTolM) << u << "," << v;
        ++checked;
      } else if (miss > 1.01 * radius) {
        EXPECT_FLOAT_EQ(image.depth_m[i], 1.5f);
      }
    }
  }
  EXPECT_GT(checked, 1000);
}

SceneConfig IdealScene(Shape shape, GraspWay grasp) {
  SceneConfig config;
  config.shape = shape;
  config.grasp = grasp;
  config.sensor = SensorModelConfig::Ideal();
  return config;
}

// Back-projects every valid pixel of every frame into the object frame and
// counts points on the top (facing the palm) and on the bottom.
struct TopBottomCounts {
  int top{0};
  int bottom{0};
  int min_object_pixels{1 << 30};
};

template <typename OnTop, typename OnBottom>
TopBottomCounts CountTopBottom(const Scene& scene, OnTop on_top, OnBottom on_bottom) {
  const SceneRenderer renderer(scene);
  TopBottomCounts counts;
  const Eigen::Isometry3d T_O_G = scene.placement().T_G_O.inverse();
  for (int f = 0; f < scene.num_frames(); ++f) {
    const DepthFrame frame = renderer.Render(f);
    const CameraIntrinsics& k = frame.intrinsics;
    const Eigen::Isometry3d T_O_C = T_O_G * scene.T_C_G_AtUtime(frame.utime).inverse();
    int object_pixels = 0;
    for (int v = 0; v < k.height; ++v) {
      for (int u = 0; u < k.width; ++u) {
        const float z = frame.at(u, v);
        // The object is ~0.55 m away; the wall (1.4 m) cannot project onto it.
        if (z <= 0.0f || z > 1.0f) continue;
        const Eigen::Vector3d p_O = T_O_C * (z * RayC(k, u, v));
        if (std::abs(p_O.x()) < 0.2 && std::abs(p_O.y()) < 0.2 && p_O.z() > -0.01 && p_O.z() < 0.3) {
          ++object_pixels;
        }
        counts.top += on_top(p_O);
        counts.bottom += on_bottom(p_O);
      }
    }
    counts.min_object_pixels = std::min(counts.min_object_pixels, object_pixels);
  }
  return counts;
}

// Back-projected points within 1 mm of a face and 2 mm inside its rim.
constexpr double kFaceTolM = 0.001;
constexpr double kRimM = 0.002;

TEST(SceneRendererTest, CuboidTopIsNeverSeen) {
  for (GraspWay grasp : {GraspWay::kTopStraight, GraspWay::kTopOblique, GraspWay::kMiddleStraight}) {
    const Scene scene(IdealScene(Shape::kCuboid, grasp));
    const Eigen::Vector3d s = DefaultSize(Shape::kCuboid);
    auto inside = [&](const Eigen::Vector3d& p) {
      return std::abs(p.x()) < 0.5 * s.x() - kRimM && std::abs(p.y()) < 0.5 * s.y() - kRimM;
    };
    const TopBottomCounts counts = CountTopBottom(
        scene, [&](const Eigen::Vector3d& p) { return inside(p) && std::abs(p.z() - s.z()) < kFaceTolM; },
        [&](const Eigen::Vector3d& p) { return inside(p) && std::abs(p.z()) < kFaceTolM; });
    EXPECT_EQ(counts.top, 0) << GraspWayName(grasp);
    EXPECT_GT(counts.bottom, 1000) << GraspWayName(grasp);
    EXPECT_GT(counts.min_object_pixels, 3000) << GraspWayName(grasp);
  }
}

TEST(SceneRendererTest, CylinderTopIsNeverSeen) {
  const Scene scene(IdealScene(Shape::kCylinder, GraspWay::kTopOblique));
  const Eigen::Vector3d s = DefaultSize(Shape::kCylinder);
  auto inside = [&](const Eigen::Vector3d& p) { return std::hypot(p.x(), p.y()) < 0.5 * s.x() - kRimM; };
  const TopBottomCounts counts = CountTopBottom(
      scene, [&](const Eigen::Vector3d& p) { return inside(p) && std::abs(p.z() - s.z()) < kFaceTolM; },
      [&](const Eigen::Vector3d& p) { return inside(p) && std::abs(p.z()) < kFaceTolM; });
  EXPECT_EQ(counts.top, 0);
  EXPECT_GT(counts.bottom, 1000);
}

TEST(SceneRendererTest, SphereTopCapIsNeverSeen) {
  const Scene scene(IdealScene(Shape::kSphere, GraspWay::kTopStraight));
  const double r = 0.5 * DefaultSize(Shape::kSphere).x();
  // Cap within 20 deg of the pole: the camera, 25 deg below, sees at most
  // ~61 deg of latitude over the top.
  const double cos_cap = std::cos(20.0 * kPi / 180.0);
  auto latitude_cos = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d q = p - Eigen::Vector3d(0, 0, r);
    return std::abs(q.norm() - r) < kFaceTolM ? q.z() / q.norm() : 0.0;
  };
  const TopBottomCounts counts = CountTopBottom(
      scene, [&](const Eigen::Vector3d& p) { return latitude_cos(p) > cos_cap; },
      [&](const Eigen::Vector3d& p) { return latitude_cos(p) < -cos_cap; });
  EXPECT_EQ(counts.top, 0);
  EXPECT_GT(counts.bottom, 1000);
}

TEST(SceneRendererTest, FramesAreDeterministic) {
  const SceneConfig config;
  const Scene scene_a(config);
  const Scene scene_b(config);
  const SceneRenderer a(scene_a);
  const SceneRenderer b(scene_b);
  for (int f : {0, 7, 89}) {
    const DepthFrame fa = a.Render(f);
    const DepthFrame fb = b.Render(f);
    const DepthFrame fa2 = a.Render(f);
    ASSERT_EQ(fa.depth_m.size(), fb.depth_m.size());
    EXPECT_EQ(fa.utime, fb.utime);
    EXPECT_EQ(0, std::memcmp(fa.depth_m.data(), fb.depth_m.data(), fa.depth_m.size() * sizeof(float)));
    EXPECT_EQ(0, std::memcmp(fa.depth_m.data(), fa2.depth_m.data(), fa.depth_m.size() * sizeof(float)));
  }
  SceneConfig other = config;
  other.seed = 2;
  const Scene scene_c(other);
  EXPECT_NE(SceneRenderer(scene_c).Render(7).depth_m, a.Render(7).depth_m);
  EXPECT_NE(a.Render(8).depth_m, a.Render(7).depth_m);
}

TEST(SceneRendererTest, SeesObjectClawArmAndWall) {
  const Scene scene(SceneConfig{});
  const SceneRenderer renderer(scene);
  const IdealDepthImage ideal = renderer.RenderIdeal(0);
  int counts[5] = {0, 0, 0, 0, 0};
  for (SurfaceLabel label : ideal.label) ++counts[static_cast<int>(label)];
  EXPECT_EQ(counts[static_cast<int>(SurfaceLabel::kNone)], 0);
  EXPECT_GT(counts[static_cast<int>(SurfaceLabel::kObject)], 5000);
  EXPECT_GT(counts[static_cast<int>(SurfaceLabel::kClaw)], 500);
  EXPECT_GT(counts[static_cast<int>(SurfaceLabel::kArm)], 500);
  EXPECT_GT(counts[static_cast<int>(SurfaceLabel::kBackground)], 200000);
  // The noisy frame stays within 5 sigma (+ quantization) of the truth.
  const DepthFrame frame = renderer.Render(0);
  const SensorModelConfig& sensor = scene.config().sensor;
  int valid = 0;
  for (size_t i = 0; i < frame.depth_m.size(); ++i) {
    if (frame.depth_m[i] <= 0.0f) continue;
    ++valid;
    const double z = ideal.depth_m[i];
    const double sigma = AxialNoiseSigma(sensor, z, std::acos(ideal.cos_incidence[i]));
    ASSERT_NEAR(frame.depth_m[i], z, 5.0 * sigma + z * z / (8.0 * 0.075 * 525.0));
  }
  EXPECT_GT(valid, 0.95 * frame.depth_m.size());
}

TEST(SceneRendererTest, RenderTimePerFrame) {
  const Scene scene(SceneConfig{});
  const SceneRenderer renderer(scene);
  renderer.Render(0);  // warm-up
  const int frames = 10;
  const auto start = std::chrono::steady_clock::now();
  for (int f = 0; f < frames; ++f) renderer.Render(f * 9);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() / frames;
  std::printf("render + sensor model, 640x480: %.1f ms/frame\n", ms);
  RecordProperty("render_ms_per_frame", std::to_string(ms));
#ifdef NDEBUG
  EXPECT_LT(ms, 500.0);  // generous: loaded CI machines (~25-45 ms here)
#endif
}

// A slip (object_slip.hpp): the frames before it are those of the scene
// without one; afterwards the object's pixels lie on the object moved by the
// slip's displacement, off where it was, and the claw has not moved.
TEST(SceneRendererTest, SlipMovesTheObjectAndNothingElse) {
  SceneConfig config = IdealScene(Shape::kSphere, GraspWay::kTopStraight);
  config.seed = 4;
  const Scene still(config);
  config.slip.distance_m = 0.003;
  const Scene slipping(config);
  const SceneRenderer still_renderer(still);
  const SceneRenderer renderer(slipping);
  const ObjectSlip& slip = slipping.slip();
  ASSERT_TRUE(slip.config().any());

  int before = 0;  // the last frame before the slip starts
  while (before + 1 < slipping.num_frames() && slipping.DepthUtime(before + 1) <= slip.start_utime()) {
    ++before;
  }
  ASSERT_GT(before, 10);
  for (int f : {0, before}) {
    const IdealDepthImage a = still_renderer.RenderIdeal(f);
    const IdealDepthImage b = renderer.RenderIdeal(f);
    EXPECT_EQ(a.depth_m, b.depth_m) << "frame " << f;
    EXPECT_EQ(a.label, b.label) << "frame " << f;
  }

  const int last = slipping.num_frames() - 1;
  ASSERT_GE(slipping.DepthUtime(last), slip.end_utime());
  const IdealDepthImage moved = renderer.RenderIdeal(last);
  const IdealDepthImage unmoved = still_renderer.RenderIdeal(last);
  const CameraIntrinsics& k = moved.intrinsics;
  const Eigen::Isometry3d T_G_C = slipping.T_C_G_AtUtime(slipping.DepthUtime(last)).inverse();
  const double r = 0.5 * DefaultSize(Shape::kSphere).x();
  const Eigen::Vector3d centre_G = mesh::Bounds(slipping.object_G()).center();
  const Eigen::Vector3d d = slip.Displacement_G();
  std::vector<double> to_moved, to_unmoved;
  int claw_same = 0, claw_differs = 0;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const size_t i = static_cast<size_t>(v) * k.width + u;
      if (moved.label[i] == SurfaceLabel::kClaw && unmoved.label[i] == SurfaceLabel::kClaw) {
        (moved.depth_m[i] == unmoved.depth_m[i] ? claw_same : claw_differs) += 1;
      }
      if (moved.label[i] != SurfaceLabel::kObject) continue;
      const Eigen::Vector3d p_G = T_G_C * (moved.depth_m[i] * RayC(k, u, v));
      to_moved.push_back(std::abs((p_G - centre_G - d).norm() - r));
      to_unmoved.push_back(std::abs((p_G - centre_G).norm() - r));
    }
  }
  ASSERT_GT(to_moved.size(), 3000u);
  std::sort(to_moved.begin(), to_moved.end());
  std::sort(to_unmoved.begin(), to_unmoved.end());
  // A 128-segment sphere: ~10 um off the true one radially, more along
  // grazing rays at the silhouette.
  EXPECT_LT(to_moved[to_moved.size() * 99 / 100], 1e-4);
  // The camera sees the sphere's side and bottom (+z_G side), the slide is
  // within 15 deg of +z_G: a point with normal n moved d . n off the unmoved
  // sphere, over 0.75 mm for most of them.
  EXPECT_GT(to_unmoved[to_unmoved.size() / 2], 0.25 * 0.003);
  EXPECT_GT(claw_same, 500);
  EXPECT_EQ(claw_differs, 0);
}

IdealDepthImage FlatImage(double z, double cos_incidence) {
  IdealDepthImage image;
  const size_t n = static_cast<size_t>(image.intrinsics.width) * image.intrinsics.height;
  image.depth_m.assign(n, static_cast<float>(z));
  image.cos_incidence.assign(n, static_cast<float>(cos_incidence));
  image.label.assign(n, SurfaceLabel::kObject);
  return image;
}

void MeanStd(const DepthFrame& frame, double z, double* mean, double* std, double* valid) {
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (float d : frame.depth_m) {
    if (d <= 0.0f) continue;
    sum += d - z;
    sum2 += (d - z) * (d - z);
    ++n;
  }
  *mean = sum / n;
  *std = std::sqrt(sum2 / n - *mean * *mean);
  *valid = static_cast<double>(n) / frame.depth_m.size();
}

TEST(SensorModelTest, AxialNoiseMatchesNguyen) {
  const double z = 0.8;
  EXPECT_NEAR(AxialNoiseSigma(SensorModelConfig{}, z, 0.0), 0.0012 + 0.0019 * 0.16, 1e-12);
  SensorModelConfig config = SensorModelConfig::Ideal();
  config.noise = true;
  double mean, std, valid;
  MeanStd(ApplySensorModel(config, FlatImage(z, 1.0), 5, 0), z, &mean, &std, &valid);
  const double sigma = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4);
  EXPECT_NEAR(std, sigma, 0.02 * sigma);  // 307k samples: ~0.2 % std error
  EXPECT_NEAR(mean, 0.0, 2e-5);
  EXPECT_EQ(valid, 1.0);

  // Kinect defaults: noise plus 1/8-px disparity steps (uniform rounding
  // adds step^2 / 12 to the variance), 0.5 % random loss.
  MeanStd(ApplySensorModel(SensorModelConfig{}, FlatImage(z, 1.0), 5, 0), z, &mean, &std, &valid);
  const double step = z * z / (0.075 * 525.0 * 8.0);
  EXPECT_NEAR(std, std::sqrt(sigma * sigma + step * step / 12.0), 0.1 * sigma);
  EXPECT_NEAR(valid, 0.995, 0.001);
}

// An uncalibrated sensor: depth scaled, focal lengths stated off, and a
// slow wobble of the whole frame, each as configured and nothing else.
TEST(SensorModelTest, ScaleIntrinsicsAndWobbleAreAppliedAsConfigured) {
  const double z = 0.6;
  SensorModelConfig config = SensorModelConfig::Ideal();
  config.depth_scale = 1.01;
  config.intrinsics_scale = 1.005;
  double mean, std, valid;
  const DepthFrame scaled = ApplySensorModel(config, FlatImage(z, 1.0), 5, 0);
  MeanStd(scaled, z, &mean, &std, &valid);
  EXPECT_NEAR(mean, 0.01 * z, 1e-6);  // 6 mm long at 0.6 m
  EXPECT_EQ(valid, 1.0);
  for (float d : scaled.depth_m) ASSERT_NEAR(d, 1.01 * z, 1e-6);
  EXPECT_NEAR(scaled.intrinsics.fx, 525.0 * 1.005, 1e-9);
  EXPECT_NEAR(scaled.intrinsics.fy, 525.0 * 1.005, 1e-9);
  EXPECT_EQ(scaled.intrinsics.cx, FlatImage(z, 1.0).intrinsics.cx);

  config = SensorModelConfig::Ideal();
  config.wobble_m = 0.0005;
  config.wobble_period_s = 2.0;
  MeanStd(ApplySensorModel(config, FlatImage(z, 1.0), 5, 500000), z, &mean, &std, &valid);
  EXPECT_NEAR(mean, 0.0005, 1e-6);  // a quarter period: the crest
  const DepthFrame trough = ApplySensorModel(config, FlatImage(z, 1.0), 5, 1500000);
  for (float d : trough.depth_m) ASSERT_NEAR(d, z - 0.0005, 1e-6);  // the whole frame, together

  SensorModelConfig bad;
  bad.depth_scale = 0.0;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  bad = SensorModelConfig{};
  bad.wobble_period_s = 0.0;
  bad.wobble_m = 0.001;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
}

TEST(SensorModelTest, QuantizationSteps) {
  const SensorModelConfig config;
  const double z = QuantizeDepth(config, 525.0, 1.0);
  EXPECT_NEAR(z, 1.0, 0.5 * 1.0 / (0.075 * 525.0 * 8.0) + 1e-9);
  EXPECT_DOUBLE_EQ(QuantizeDepth(config, 525.0, z), z);
  const DepthFrame frame = ApplySensorModel(config, FlatImage(1.0, 1.0), 9, 0);
  for (size_t i = 0; i < frame.depth_m.size(); i += 101) {
    if (frame.depth_m[i] <= 0.0f) continue;
    const double d = 0.075 * 525.0 / frame.depth_m[i] * 8.0;
    ASSERT_NEAR(d, std::round(d), 1e-3);  // an integer number of 1/8 px
  }
}

TEST(SensorModelTest, DropoutsAtGrazingAnglesEdgesAndRange) {
  const SensorModelConfig config;
  double mean, std, valid;
  MeanStd(ApplySensorModel(config, FlatImage(0.8, std::cos(85.0 * kPi / 180.0)), 1, 0), 0.8, &mean, &std,
          &valid);
  EXPECT_EQ(valid, 0.0);  // all lost past 82 deg
  MeanStd(ApplySensorModel(config, FlatImage(0.8, std::cos(60.0 * kPi / 180.0)), 1, 0), 0.8, &mean, &std,
          &valid);
  EXPECT_NEAR(valid, 0.995, 0.001);  // only random loss at 60 deg
  MeanStd(ApplySensorModel(config, FlatImage(0.2, 1.0), 1, 0), 0.2, &mean, &std, &valid);
  EXPECT_EQ(std::isnan(mean) || valid == 0.0, true);  // nearer than 0.3 m
  MeanStd(ApplySensorModel(config, FlatImage(3.5, 1.0), 1, 0), 3.5, &mean, &std, &valid);
  EXPECT_EQ(std::isnan(mean) || valid == 0.0, true);  // beyond 3 m

  // A step edge between columns 319 and 320: those two columns lose ~half.
  IdealDepthImage step = FlatImage(0.6, 1.0);
  const int w = step.intrinsics.width;
  for (size_t i = 0; i < step.depth_m.size(); ++i) {
    if (static_cast<int>(i % w) >= 320) step.depth_m[i] = 1.0f;
  }
  const DepthFrame frame = ApplySensorModel(config, step, 3, 0);
  int edge_valid = 0, edge_total = 0, inner_valid = 0, inner_total = 0;
  for (int v = 0; v < step.intrinsics.height; ++v) {
    for (int u = 0; u < w; ++u) {
      const bool edge = u == 319 || u == 320;
      (edge ? edge_total : inner_total) += 1;
      (edge ? edge_valid : inner_valid) += frame.at(u, v) > 0.0f;
    }
  }
  EXPECT_NEAR(static_cast<double>(edge_valid) / edge_total, 0.5 * 0.995, 0.06);
  EXPECT_NEAR(static_cast<double>(inner_valid) / inner_total, 0.995, 0.002);
}

}  // namespace
}  // namespace graspfill::synth
