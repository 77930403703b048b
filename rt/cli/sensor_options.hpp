// SPDX-License-Identifier: BSD-3-Clause
// The sensor-artefact options both benches that render scenes take
// (`bench repair --objects` and `bench repair --pipeline`): the artefacts
// `graspfill synth` models, and the pipeline's depth-edge rule.
#pragma once

#include <functional>
#include <string>

#include "synth/sensor_model.hpp"

namespace graspfill::cli {

struct SensorOptions {
  synth::SensorModelConfig sensor;  ///< the artefacts asked for (none by default)
  bool reject_depth_edges{false};   ///< PipelineConfig::reject_depth_edges
};

/// Their lines for a usage text.
extern const char* const kSensorOptionsUsage;

/// Takes option `a` into *o when it is one of them (`value` gives its
/// value); false when `a` is not.
/// @throws UsageError on a bad value.
bool ParseSensorOption(const std::string& a, const std::function<std::string()>& value, SensorOptions* o);

/// ", depth edges dropped, projector shadow, ..." ("" for none).
std::string SensorOptionsText(const SensorOptions& o);

}  // namespace graspfill::cli
