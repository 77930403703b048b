// SPDX-License-Identifier: BSD-3-Clause
// A downstream program, built against graspfill as its users build it
// (find_package, add_subdirectory or pkg-config; tests/install/): the
// README's grasp-loop snippet on a recording, then the repair, then the
// cloud through the generated LCM type. Exit code 0 when every check holds.
//
// usage: grasp_loop RECORDING.lcmlog
#include <cstdio>
#include <string>
#include <vector>

#include "graspfill/io/messages.hpp"
#include "graspfill/object_cloud_t.hpp"
#include "graspfill/pipeline/pipeline.hpp"
#include "graspfill/repair/repairer.hpp"
#include "sources/lcm_log_source.hpp"

namespace {

// The recording's depth frames see the object whole but for the claw and
// the top: the fused cloud of the bundled recording has ~20,600 points.
constexpr size_t kMinFusedPoints = 5000;

int failures = 0;

void Check(bool ok, const std::string& what) {
  std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
  if (!ok) ++failures;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: grasp_loop RECORDING.lcmlog\n");
    return 2;
  }

  // The README's snippet, fed from the log.
  graspfill::PipelineConfig config;  // documented defaults
  graspfill::Pipeline pipeline(config, graspfill::claw::ClawModel::ThreeFinger());
  graspfill::rt::LcmLogSource::Config log;
  log.path = argv[1];
  graspfill::rt::LcmLogSource source(log);
  graspfill::rt::SourceEvent event;
  for (graspfill::rt::FrameResult r; (r = source.Next(&event)) != graspfill::rt::FrameResult::kEndOfStream;) {
    if (r != graspfill::rt::FrameResult::kOk) continue;
    if (event.kind == graspfill::rt::SourceEvent::Kind::kDepth) {
      pipeline.AddDepthFrame(event.depth);
    } else if (event.kind == graspfill::rt::SourceEvent::Kind::kGripperState) {
      pipeline.AddGripperState(event.gripper);
    }
  }
  pipeline.Flush();
  const graspfill::ObjectCloud cloud = pipeline.ExtractCloud();

  std::printf("frames integrated %lld, points %zu\n",
              static_cast<long long>(pipeline.stats().frames_integrated), cloud.size());
  Check(pipeline.stats().frames_integrated > 0, "frames integrated");
  Check(cloud.size() > kMinFusedPoints, "more than 5000 fused points");
  size_t outside = 0;
  for (const Eigen::Vector3f& p : cloud.points_G) {
    if (!config.workspace.Contains(p.cast<double>())) ++outside;
  }
  Check(outside == 0, "every point in the workspace box (" + std::to_string(outside) + " outside)");
  Check(cloud.normals_G.size() == cloud.size(), "one normal per point");

  // The repair, as the README shows it.
  graspfill::repair::RepairConfig repair;
  repair.up_hint = Eigen::Vector3d(0, 0, -1);
  const graspfill::repair::RepairResult r = graspfill::repair::Repair(cloud, repair);
  std::printf("repair: %s, %zu -> %zu points\n", r.report.StatusText().c_str(), cloud.size(), r.cloud.size());
  Check(r.report.status == graspfill::repair::RepairStatus::kRepaired, "the repair ran");
  Check(r.cloud.size() > cloud.size(), "the repair added points");
  bool unchanged = r.cloud.size() >= cloud.size();
  for (size_t i = 0; unchanged && i < cloud.size(); ++i) {
    unchanged = r.cloud.points_G[i] == cloud.points_G[i];
  }
  Check(unchanged, "the fused points come first, unchanged");

  // Through the generated message type (graspfill::lcmtypes).
  const std::vector<uint8_t> bytes = graspfill::io::EncodeObjectCloud(r.cloud);
  graspfill::object_cloud_t message;
  const int used = message.decode(bytes.data(), 0, static_cast<int>(bytes.size()));
  Check(used == static_cast<int>(bytes.size()), "object_cloud_t decodes");
  Check(message.num_points == static_cast<int>(r.cloud.size()), "object_cloud_t carries every point");

  std::printf("%s\n", failures == 0 ? "PASSED" : "FAILED");
  return failures == 0 ? 0 : 1;
}
