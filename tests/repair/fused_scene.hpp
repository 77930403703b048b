// SPDX-License-Identifier: BSD-3-Clause
// A synthetic grasp fused in-process as a replay would: every depth frame
// rendered, sent through the bus encoding (zlib16, 1 mm steps) and fused.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "eval/metrics.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/mesh/nearest_distances.hpp"
#include "graspfill/pipeline/pipeline.hpp"
#include "synth/renderer.hpp"
#include "synth/scene.hpp"

namespace graspfill::testing {

/// Feeds `scene`'s timeline to `pipeline`; `after_state` (optional) runs
/// after each gripper state with the depth frames fed so far. Flushes at
/// the end.
inline void FuseScene(const synth::Scene& scene, Pipeline* pipeline,
                      const std::function<void(int frames)>& after_state = {}) {
  const synth::SceneRenderer renderer(scene);
  DepthFrame frame;
  std::string error;
  int frames = 0;
  for (const synth::TimelineEvent& e : scene.Timeline()) {
    if (e.kind == synth::TimelineEvent::Kind::kDepth) {
      const auto bytes = io::EncodeDepthImage(renderer.Render(e.index), io::DepthEncoding::kZlib16, 0.001);
      EXPECT_TRUE(io::DecodeDepthImage(bytes.data(), bytes.size(), &frame, &error)) << error;
      pipeline->AddDepthFrame(frame);
      ++frames;
    } else {
      pipeline->AddGripperState(scene.GripperStateAt(e.utime));
      if (after_state) after_state(frames);
    }
  }
  pipeline->Flush();
}

/// Share of `truth` within 2 mm of `cloud` (the zoo's coverage).
inline double Coverage(const ObjectCloud& cloud, const std::vector<Eigen::Vector3f>& truth) {
  return eval::FractionWithin(mesh::NearestDistances(truth, cloud.points_G), 0.002);
}

}  // namespace graspfill::testing
