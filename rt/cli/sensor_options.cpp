// SPDX-License-Identifier: BSD-3-Clause
#include "sensor_options.hpp"

#include <cstdio>

#include "number_parsing.hpp"

namespace graspfill::cli {

const char* const kSensorOptionsUsage =
    "  --reject-depth-edges  the pipeline drops the pixels on depth edges (off by\n"
    "                default; docs/measurements/2026-12-07-depth-edges-again.md)\n"
    "  --projector-shadow, --dark-patches F, --mixed-pixels P, --wobble-mm A,\n"
    "  --depth-scale S  the sensor's artefacts, as `graspfill synth` makes them\n"
    "                (none by default)\n";

bool ParseSensorOption(const std::string& a, const std::function<std::string()>& value, SensorOptions* o) {
  if (a == "--reject-depth-edges")
    o->reject_depth_edges = true;
  else if (a == "--projector-shadow")
    o->sensor.projector_shadow = true;
  else if (a == "--dark-patches")
    o->sensor.dark_patch_share = ParseDouble(a, value(), 0.0, 0.5, "");
  else if (a == "--mixed-pixels")
    o->sensor.mixed_pixel_prob = ParseDouble(a, value(), 0.0, 1.0, "");
  else if (a == "--wobble-mm")
    o->sensor.wobble_m = 0.001 * ParseDouble(a, value(), 0.0, 5.0, "mm");
  else if (a == "--depth-scale")
    o->sensor.depth_scale = ParseDouble(a, value(), 0.9, 1.1, "");
  else
    return false;
  return true;
}

std::string SensorOptionsText(const SensorOptions& o) {
  std::string text;
  const auto add = [&](const char* format, double x) {
    char item[64];
    std::snprintf(item, sizeof(item), format, x);
    text += item;
  };
  if (o.reject_depth_edges) text += ", depth edges dropped";
  if (o.sensor.projector_shadow) text += ", projector shadow";
  if (o.sensor.dark_patch_share > 0.0) add(", dark patches %.0f%%", 100.0 * o.sensor.dark_patch_share);
  if (o.sensor.mixed_pixel_prob > 0.0) add(", mixed pixels %.2f", o.sensor.mixed_pixel_prob);
  if (o.sensor.wobble_m > 0.0) add(", wobble %.1f mm", 1000.0 * o.sensor.wobble_m);
  if (o.sensor.depth_scale != 1.0) add(", depth x %.3f", o.sensor.depth_scale);
  return text;
}

}  // namespace graspfill::cli
