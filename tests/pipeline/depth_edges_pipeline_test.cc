// SPDX-License-Identifier: BSD-3-Clause
// Mixed pixels through the whole pipeline: a box rendered by a sensor whose
// every kept edge pixel returns a depth between the edge's two sides (the
// flying pixels of synth's --mixed-pixels 1) leaves points floating off
// the box when fused as measured, and none once the pixels on depth edges
// are rejected (fusion/depth_edges.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "../repair/fused_scene.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "graspfill/mesh/nearest_distances.hpp"
#include "graspfill/pipeline/pipeline.hpp"
#include "synth/scene.hpp"

namespace graspfill {
namespace {

struct Fused {
  size_t points{0};
  size_t off_object{0};  // farther than 5 mm from the box's surface
  double p99_mm{0.0}, max_mm{0.0};
  int64_t edge_pixels{0};
};

Fused FuseBox(double mixed_pixel_prob, bool reject_edges) {
  synth::SceneConfig sc;
  sc.shape = synth::Shape::kRoundedBox;
  sc.claw = synth::ClawType::kParallel;
  sc.num_frames = 45;
  sc.seed = 4;
  sc.sensor.mixed_pixel_prob = mixed_pixel_prob;
  const synth::Scene scene(sc);
  PipelineConfig config;
  config.reject_depth_edges = reject_edges;
  Pipeline pipeline(config, scene.MakeClawModel());
  testing::FuseScene(scene, &pipeline);
  const ObjectCloud cloud = pipeline.ExtractCloud();
  const std::vector<Eigen::Vector3f> truth = mesh::SampleSurface(scene.object_G(), 100000, 3).points;
  const std::vector<double> d = mesh::NearestDistances(cloud.points_G, truth);
  Fused f;
  f.points = cloud.size();
  f.off_object = static_cast<size_t>(std::count_if(d.begin(), d.end(), [](double x) { return x > 0.005; }));
  f.edge_pixels = pipeline.stats().depth_edge_pixels;
  std::vector<double> sorted = d;
  std::sort(sorted.begin(), sorted.end());
  f.p99_mm = 1000.0 * sorted[sorted.size() * 99 / 100];
  f.max_mm = 1000.0 * sorted.back();
  std::printf("mixed %.1f edges %s: %zu points, %zu > 5 mm, p99 %.2f mm, max %.2f mm, %lld edge pixels\n",
              mixed_pixel_prob, reject_edges ? "rejected" : "kept", f.points, f.off_object, f.p99_mm,
              f.max_mm, static_cast<long long>(f.edge_pixels));
  return f;
}

TEST(DepthEdgesInThePipeline, FlyingPixelsLeaveNoPointOffTheObject) {
  const Fused measured = FuseBox(1.0, false);
  const Fused rejected = FuseBox(1.0, true);
  ASSERT_GT(measured.points, 2000u);
  ASSERT_GT(rejected.points, 2000u);
  // The counter-check: fused as measured, some flying pixels outlive the
  // free space later frames carve and float off the box (most do not).
  EXPECT_GT(measured.off_object, 0u);
  EXPECT_EQ(measured.edge_pixels, 0);
  // Rejected, none does.
  EXPECT_EQ(rejected.off_object, 0u);
  EXPECT_GT(rejected.edge_pixels, 0);
  // And the cloud keeps the box: the pixels dropped are a rim's worth.
  EXPECT_GT(rejected.points, measured.points * 9 / 10);
}

}  // namespace
}  // namespace graspfill
