// SPDX-License-Identifier: BSD-3-Clause
// What `graspfill synth` and `synth --grasps` both write of a scene: its
// timeline into the log, and its ground-truth cloud.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "graspfill/io/channel_names.hpp"
#include "graspfill/types.hpp"
#include "progress.hpp"
#include "sinks/lcm_log_writer.hpp"
#include "synth/scene.hpp"

namespace graspfill::cli {

/// Writes `timeline` (the scene's) into the log: each depth event rendered
/// (ZLIB16, 1 mm units), each gripper event as `state_at` makes it, stamped
/// with the event's time. *frames_done counts the depth frames on for the
/// progress line. Returns the gripper states written.
int64_t WriteSceneEvents(const synth::Scene& scene, const std::vector<synth::TimelineEvent>& timeline,
                         const std::function<GripperState(const synth::TimelineEvent&)>& state_at,
                         const io::ChannelNames& channels, rt::LcmLogWriter* log, ProgressLine* progress,
                         int64_t* frames_done);

/// synth::kDefaultGroundTruthPoints points sampled (seeded) on the object
/// in G, with their normals, stamped as the first depth frame.
ObjectCloud GroundTruthCloud(const synth::Scene& scene, uint64_t seed);

}  // namespace graspfill::cli
