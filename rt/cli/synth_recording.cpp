// SPDX-License-Identifier: BSD-3-Clause
#include "synth_recording.hpp"

#include "graspfill/io/messages.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "synth/renderer.hpp"

namespace graspfill::cli {

int64_t WriteSceneEvents(const synth::Scene& scene, const std::vector<synth::TimelineEvent>& timeline,
                         const std::function<GripperState(const synth::TimelineEvent&)>& state_at,
                         const io::ChannelNames& channels, rt::LcmLogWriter* log, ProgressLine* progress,
                         int64_t* frames_done) {
  const synth::SceneRenderer renderer(scene);
  int64_t states = 0;
  for (const synth::TimelineEvent& event : timeline) {
    if (event.kind == synth::TimelineEvent::Kind::kDepth) {
      log->Write(channels.depth, event.utime,
                 io::EncodeDepthImage(renderer.Render(event.index), io::DepthEncoding::kZlib16, 0.001));
      progress->Update(++*frames_done);
    } else {
      log->Write(channels.gripper_state, event.utime, io::EncodeGripperState(state_at(event)));
      ++states;
    }
  }
  return states;
}

ObjectCloud GroundTruthCloud(const synth::Scene& scene, uint64_t seed) {
  const mesh::SurfaceSamples samples =
      mesh::SampleSurface(scene.object_G(), synth::kDefaultGroundTruthPoints, seed);
  ObjectCloud gt;
  gt.utime = scene.DepthUtime(0);
  gt.T_C_G = scene.T_C_G(0.0);
  gt.points_G = samples.points;
  gt.normals_G = samples.normals;
  return gt;
}

}  // namespace graspfill::cli
