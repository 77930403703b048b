// SPDX-License-Identifier: BSD-3-Clause
#include "bench_pipeline_parts.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <utility>

#include "eval/metrics.hpp"
#include "graspfill/core/percentile.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/mesh/nearest_distances.hpp"
#include "module/cloud_repair.hpp"
#include "synth/renderer.hpp"

namespace graspfill::cli {
namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

std::unique_ptr<Pipeline> RunSceneThroughPipeline(const synth::Scene& scene, const PipelineConfig& config) {
  const synth::SceneRenderer renderer(scene);
  auto pipeline = std::make_unique<Pipeline>(config, scene.MakeClawModel());
  DepthFrame frame;
  for (const synth::TimelineEvent& e : scene.Timeline()) {
    if (e.kind == synth::TimelineEvent::Kind::kDepth) {
      const std::vector<uint8_t> bytes =
          io::EncodeDepthImage(renderer.Render(e.index), io::DepthEncoding::kZlib16, 0.001);
      std::string error;
      if (!io::DecodeDepthImage(bytes.data(), bytes.size(), &frame, &error)) {
        throw std::runtime_error(error);
      }
      pipeline->AddDepthFrame(frame);
    } else {
      pipeline->AddGripperState(scene.GripperStateAt(e.utime));
    }
  }
  pipeline->Flush();
  return pipeline;
}

mesh::SurfaceSamples TruthSamples(const synth::Scene& scene) {
  return mesh::SampleSurface(scene.object_G(), 200000, 5);
}

FusedMeasures MeasureFused(const ObjectCloud& fused, const std::vector<Eigen::Vector3f>& truth) {
  FusedMeasures m;
  m.coverage = eval::FractionWithin(mesh::NearestDistances(truth, fused.points_G), kCoverageRadiusM);
  const std::vector<double> to_truth = mesh::NearestDistances(fused.points_G, truth);
  m.p95_mm = 1000.0 * Percentile(to_truth, 95.0);
  m.p99_mm = 1000.0 * Percentile(to_truth, 99.0);
  m.off_object_share = 1.0 - eval::FractionWithin(to_truth, kWrongDistanceM);
  return m;
}

Outcome Measure(const ObjectCloud& cloud, size_t fused, const std::vector<Eigen::Vector3f>& truth,
                const evidence::VisibilityRecord& record) {
  Outcome o;
  o.points = cloud.size();
  o.added = cloud.size() - fused;
  const std::vector<double> gt_to_cloud = mesh::NearestDistances(truth, cloud.points_G);
  o.coverage = eval::FractionWithin(gt_to_cloud, kCoverageRadiusM);
  if (o.added > 0) {
    const std::vector<Eigen::Vector3f> added(cloud.points_G.begin() + static_cast<long>(fused),
                                             cloud.points_G.end());
    const std::vector<double> d = mesh::NearestDistances(added, truth);
    o.added_p95_mm = 1000.0 * Percentile(d, 95.0);
    o.added_wrong = 1.0 - eval::FractionWithin(d, kWrongDistanceM);
    if (cloud.confidence.size() == cloud.size()) {
      std::vector<double> trusted;
      for (size_t k = 0; k < d.size(); ++k) {
        if (cloud.confidence[fused + k] > 0.5f) trusted.push_back(d[k]);
      }
      o.trusted_added = trusted.size();
      if (!trusted.empty()) {
        o.trusted_p95_mm = 1000.0 * Percentile(trusted, 95.0);
        o.trusted_wrong = 1.0 - eval::FractionWithin(trusted, kWrongDistanceM);
      }
    }
    for (const Eigen::Vector3f& p : added) o.added_in_free += record.SeenFree(p);
  }
  o.truth_outside_bound = std::numeric_limits<double>::quiet_NaN();
  if (!cloud.safe_bound.empty() && !truth.empty()) {
    size_t outside = 0;
    for (const Eigen::Vector3f& p : truth) outside += !cloud.safe_bound.Contains(p);
    o.truth_outside_bound = static_cast<double>(outside) / static_cast<double>(truth.size());
  }
  return o;
}

TimedRepair RepairTimed(const ObjectCloud& fused, const evidence::VisibilityRecord* record, int repeat) {
  TimedRepair out;
  out.best_ms = std::numeric_limits<double>::infinity();
  for (int r = 0; r < repeat; ++r) {
    ObjectCloud attempt = fused;
    const Clock::time_point start = Clock::now();
    repair::RepairReport report = rt::RepairObjectCloud(rt::GripperFrameRepairConfig(), &attempt, record);
    const double ms = MsSince(start);
    if (ms < out.best_ms) out.best_ms = ms, out.best_steps = report.timings;
    if (r == 0) {
      out.cloud = std::move(attempt);
      out.report = std::move(report);
    } else if (attempt.points_G != out.cloud.points_G || attempt.normals_G != out.cloud.normals_G ||
               attempt.confidence != out.cloud.confidence) {
      throw std::runtime_error("repair " + std::to_string(r + 1) +
                               " of the same cloud differs from the first");
    }
  }
  return out;
}

std::string RepairNote(const repair::RepairReport& r) {
  std::string note = r.StatusText();
  if (!r.symmetry_reason.empty()) note += "; " + r.symmetry_reason;
  if (!r.top_completion.empty()) {
    char text[96];
    std::snprintf(text, sizeof(text), "; the top: %s, confidence %.2f", r.top_completion.c_str(),
                  r.top_confidence);
    note += text;
  }
  if (!r.evidence.top.empty()) note += "; the rays' top: " + r.evidence.top;
  if (r.claw_holes_left_open > 0) note += "; claw holes left open: " + std::to_string(r.claw_holes_left_open);
  return note;
}

std::string StepsText(const std::vector<StageTiming>& steps) {
  std::string text;
  char step[96];
  for (const StageTiming& t : steps) {
    std::snprintf(step, sizeof(step), " %s %.1f", t.stage.c_str(), t.ms);
    text += step;
  }
  return text;
}

nlohmann::ordered_json StepsJson(const std::vector<StageTiming>& steps) {
  nlohmann::ordered_json out = nlohmann::ordered_json::object();
  for (const StageTiming& t : steps) out[t.stage] = t.ms;
  return out;
}

std::string CheckDumpPaths(const std::string& dump_dir, const std::vector<std::string>& paths) {
  if (!std::filesystem::is_directory(dump_dir)) return "--dump '" + dump_dir + "' is not a directory";
  for (const std::string& path : paths) {
    if (std::filesystem::exists(path)) return "'" + path + "' exists (not overwritten)";
  }
  return "";
}

}  // namespace graspfill::cli
