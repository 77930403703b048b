// SPDX-License-Identifier: BSD-3-Clause
// What `graspfill replay` tells once the replay is done
// (rt/module/replay_session.hpp): the report as JSON (--json) or as lines
// for people.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "graspfill/pipeline/pipeline.hpp"
#include "module/replay_session.hpp"

namespace graspfill::cli {

/// The claw the replay used and where it came from.
struct ClawUse {
  std::string label;  ///< how messages name it
  std::string from;   ///< "command line", "config file", "session description" or "default"
};

/// Everything the report says, gathered by the command.
struct ReplayReport {
  const rt::ReplaySessionConfig& config;
  const rt::ReplayResult& result;  ///< a replay that ended kDone
  const Pipeline& pipeline;        ///< the last grasp's (ReplaySession::pipeline)
  ClawUse claw;
  std::string config_path;   ///< --config, "" = none
  std::string preview_path;  ///< "" = none
  /// WriteCollisionMesh's report (mesh_option.hpp); null: no --mesh-out.
  const nlohmann::ordered_json* mesh{nullptr};
};

/// --json's report.
nlohmann::ordered_json ReplayReportJson(const ReplayReport& report);

/// The report as lines on stdout, after the earlier grasps' lines
/// (PrintEarlierGrasps).
void PrintReplayReport(const ReplayReport& report);

/// One line per earlier grasp delivered (each printed once, whatever
/// happens to the grasps after it).
void PrintEarlierGrasps(const rt::ReplayResult& result);

}  // namespace graspfill::cli
