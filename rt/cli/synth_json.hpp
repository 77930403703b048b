// SPDX-License-Identifier: BSD-3-Clause
// The JSON files `graspfill synth` writes beside a recording: scene.json
// (every parameter of the scene and what followed) and claw/claw.json (the
// claw as rendered, as a description for --claw).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "graspfill/claw/claw_model.hpp"
#include "graspfill/io/atomic_file.hpp"
#include "graspfill/io/channel_names.hpp"
#include "synth/rig_errors.hpp"
#include "synth/scene.hpp"
#include "synth_options.hpp"

namespace graspfill::cli {

/// The claw model as a description file (config/claws/README.md) with one
/// PLY per link beside it, so `--claw DIR/claw/claw.json` replays with the
/// exact claw, including lengthened fingers.
void WriteClawDescription(const claw::ClawModel& model, const std::filesystem::path& dir,
                          io::IfExists if_exists);

/// scene.json of a recording: the scene, the log (`log_bytes`, its
/// gripper states), the rig's errors and, with one, the slip.
nlohmann::json SceneJson(const synth::Scene& scene, const SynthOptions& o, const io::ChannelNames& ch,
                         int64_t log_bytes, size_t gripper_states, const synth::RigErrors& rig);

}  // namespace graspfill::cli
