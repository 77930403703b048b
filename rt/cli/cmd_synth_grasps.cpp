// SPDX-License-Identifier: BSD-3-Clause
#include "cmd_synth_grasps.hpp"

#include <cstdio>
#include <exception>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "claw_option.hpp"
#include "commands.hpp"
#include "error_text.hpp"
#include "graspfill/io/atomic_file.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "number_parsing.hpp"
#include "output_dir.hpp"
#include "progress.hpp"
#include "sinks/lcm_log_writer.hpp"
#include "synth/renderer.hpp"
#include "synth/scene.hpp"
#include "synth/shapes.hpp"
#include "synth_recording.hpp"

namespace graspfill::cli {

namespace fs = std::filesystem;

namespace {
// Between two grasps: no events (the robot puts the object down).
constexpr int64_t kGapBetweenGraspsUs = 1000000;
}  // namespace

std::vector<std::string> ParseGraspShapes(const std::string& text) {
  std::vector<std::string> shapes;
  std::stringstream in(text);
  std::string name;
  while (std::getline(in, name, ',')) {
    if (!synth::ParseShape(name)) {
      throw UsageError("--grasps '" + text + "': unknown shape '" + name + "'");
    }
    shapes.push_back(name);
  }
  if (shapes.empty() || text.back() == ',') {
    throw UsageError("--grasps '" + text + "': expected shapes separated by commas");
  }
  return shapes;
}

namespace {

// One scene per grasp, each starting kGapBetweenGraspsUs after the one
// before it ends.
std::vector<synth::SceneConfig> GraspConfigs(const SynthGraspsOptions& o) {
  std::vector<synth::SceneConfig> configs;
  int64_t start_utime = synth::MotionConfig{}.start_utime;
  for (size_t k = 0; k < o.shapes.size(); ++k) {
    synth::SceneConfig config;
    config.shape = *synth::ParseShape(o.shapes[k]);
    config.claw = *synth::ParseClawType(o.claw);
    config.grasp = *synth::ParseGraspWay(o.grasp);
    config.seed = o.seed + k;
    config.num_frames = o.frames;
    if (o.ideal) config.sensor = synth::SensorModelConfig::Ideal();
    config.environment.wall_distance_m = o.wall_m;
    config.intrinsics = o.intrinsics;
    config.motion.start_utime = start_utime;
    configs.push_back(config);
    const synth::Scene scene(config);
    const std::vector<synth::TimelineEvent> timeline = scene.Timeline();
    start_utime =
        timeline.back().utime + kGapBetweenGraspsUs + static_cast<int64_t>(1e6 * config.gripper_lead_s);
  }
  return configs;
}

// Grasp k's events (its gripper states carrying grasp_id k) into the log,
// its truth into DIR/grasp<k>/; returns its entry of grasps.json.
nlohmann::ordered_json WriteGrasp(const SynthGraspsOptions& o, size_t k, const synth::SceneConfig& config,
                                  const synth::Scene& scene, const fs::path& dir, rt::LcmLogWriter* log,
                                  ProgressLine* progress, int64_t* frames_done) {
  const int64_t grasp_id = static_cast<int64_t>(k) + 1;
  const std::vector<synth::TimelineEvent> timeline = scene.Timeline();
  const int64_t states = WriteSceneEvents(
      scene, timeline,
      [&](const synth::TimelineEvent& event) {
        GripperState state = scene.GripperStateAt(event.utime);
        state.grasp_id = grasp_id;
        return state;
      },
      io::ChannelNames{}, log, progress, frames_done);
  const fs::path gdir = dir / ("grasp" + std::to_string(grasp_id));
  fs::create_directories(gdir);
  io::WriteMeshPly((gdir / "gt_mesh.ply").string(), scene.object_G(), io::ReplaceIf(o.force));
  io::WriteCloudPly((gdir / "gt_cloud.ply").string(), GroundTruthCloud(scene, config.seed),
                    io::ReplaceIf(o.force));
  progress->Clear();  // the grasp's line on a line of its own
  std::printf("grasp %lld: %s, %d depth frames + %lld gripper states\n", static_cast<long long>(grasp_id),
              o.shapes[k].c_str(), config.num_frames, static_cast<long long>(states));
  return {{"grasp_id", grasp_id},
          {"shape", o.shapes[k]},
          {"seed", config.seed},
          {"depth_frames", config.num_frames},
          {"gripper_states", states},
          {"first_utime", timeline.front().utime},
          {"last_utime", timeline.back().utime},
          {"ground_truth", gdir.filename().string() + "/gt_cloud.ply"}};
}

// The log and the truth of every grasp; false (said on stderr) when a
// shape needs other claw dimensions than the first.
bool WriteGrasps(const SynthGraspsOptions& o, const std::vector<synth::SceneConfig>& configs,
                 const fs::path& dir) {
  const io::ChannelNames channels;
  rt::LcmLogWriter log((dir / "recording.lcmlog").string(), o.force);
  nlohmann::ordered_json grasps = nlohmann::json::array();
  std::string claw_text;  // the first grasp's claw, as rendered
  int64_t total_frames = 0;
  for (const synth::SceneConfig& c : configs) total_frames += c.num_frames;
  ProgressLine progress("synth", "frames", total_frames);
  int64_t frames_done = 0;
  for (size_t k = 0; k < configs.size(); ++k) {
    const synth::Scene scene(configs[k]);
    const std::string text = ProceduralClawText(scene.placement().claw);
    if (k == 0) {
      claw_text = text;
      io::SessionDescription session;
      session.utime = scene.Timeline().front().utime;
      session.software_version = io::SoftwareVersion();
      DescribeBuiltinClaw(o.claw, scene.placement().claw, &session);
      log.Write(channels.session, session.utime, io::EncodeSessionDescription(session));
    } else if (text != claw_text) {
      std::fprintf(stderr,
                   "graspfill synth: --grasps: shape '%s' needs other claw dimensions "
                   "than the first grasp's (one claw holds every object)\n",
                   o.shapes[k].c_str());
      return false;
    }
    grasps.push_back(WriteGrasp(o, k, configs[k], scene, dir, &log, &progress, &frames_done));
  }
  log.Close();
  const nlohmann::ordered_json doc = {{"format", "graspfill-synth-grasps/1"},
                                      {"software_version", io::SoftwareVersion()},
                                      {"claw", o.claw},
                                      {"grasp", o.grasp},
                                      {"log", "recording.lcmlog"},
                                      {"grasps", grasps}};
  io::WriteFileAtomically((dir / "grasps.json").string(), doc.dump(2) + "\n", "cannot write",
                          io::ReplaceIf(o.force));
  return true;
}

}  // namespace

int RunSynthGrasps(const SynthGraspsOptions& o) {
  const std::vector<synth::SceneConfig> configs = GraspConfigs(o);
  const fs::path dir(o.output_dir);
  std::vector<std::string> outputs = {"recording.lcmlog", "grasps.json"};
  for (size_t k = 1; k <= o.shapes.size(); ++k) {
    outputs.push_back("grasp" + std::to_string(k) + "/gt_mesh.ply");
    outputs.push_back("grasp" + std::to_string(k) + "/gt_cloud.ply");
  }
  if (!PrepareOutputs(dir, outputs, o.force, "synth")) return 1;
  try {
    if (!WriteGrasps(o, configs, dir)) return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill synth: error: %s\n", ErrorText(e).c_str());
    return 1;
  }
  std::printf("wrote %s: %zu grasps\n", (dir / "recording.lcmlog").string().c_str(), o.shapes.size());
  return 0;
}

}  // namespace graspfill::cli
