// SPDX-License-Identifier: BSD-3-Clause
// graspfill bench repair --objects DIR: the meshes DIR/objects.json lists
// (object_manifest.hpp; e.g. scanned household objects) x claws x grasps x
// seeds, each through the whole pipeline (synthetic frames -> cut-out ->
// TSDF) and repaired as `replay` does (default options, best mode, with the
// camera's visibility record). Per row: the fused cloud's coverage and p99
// distance to the truth, the repaired cloud's coverage, its added points'
// p95, share > 3 mm ("wrong") and points in seen-free space, the repair's
// time, and whether the row meets its kind's targets (issue 42); then rows
// meeting them / rows per kind and per split.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "bench_pipeline_parts.hpp"
#include "commands.hpp"
#include "error_text.hpp"
#include "graspfill/core/percentile.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "number_parsing.hpp"
#include "object_manifest.hpp"
#include "object_mesh.hpp"
#include "progress.hpp"
#include "sensor_options.hpp"
#include "synth/scene.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {
namespace {

constexpr const char* kObjectsBenchCommand = "graspfill bench repair --objects";

constexpr const char* kObjectsBenchOptions =
    "usage: graspfill bench repair --objects DIR [--object NAME[,NAME..]] [--split tune|check]\n"
    "                              [--claw three-finger,parallel] [--grasp WAY[,WAY..]]\n"
    "                              [--seeds 1,2,3] [--frames N] [--repeat N] [--dump OUT]\n"
    "                              [--reject-depth-edges] [--verbose] [--json]\n"
    "                              [--projector-shadow] [--dark-patches F] [--mixed-pixels P]\n"
    "                              [--wobble-mm A] [--depth-scale S]\n"
    "  DIR/objects.json lists the meshes (meters, +z up; PLY, OBJ or STL) as\n"
    "    {\"objects\": {\"NAME\": {\"file\": \"NAME.ply\", \"kind\": K, \"split\": S}, ...}}\n"
    "    K closed_symmetric, closed_asymmetric or open; S tune or check; optional\n"
    "    \"mesh_scale\" (0.001: a mesh in mm) and \"mesh_up\" (\"y\": turned onto +z)\n"
    "  every object x claw x grasp x seed: synth -> pipeline -> repair with the record\n"
    "  --object      only these objects          --split   only this split\n"
    "  --claw        default three-finger,parallel\n"
    "  --grasp       default top-straight,middle-straight,top-oblique\n"
    "  --seeds       the scenes' noise and wobble (default 1,2,3)\n"
    "  --frames N    depth frames per scene, one turn (default 90)\n"
    "  --repeat N    repairs of each cloud, the fastest timed (default 3; each must\n"
    "                give the same cloud)\n"
    "  --dump OUT    each row's truth, fused and repaired clouds as PLY in OUT\n"
    "                (an existing folder; no file there is overwritten)\n"
    "  --json        rows add the fused cloud's p95 and the share of it more than\n"
    "                3 mm from the truth\n";

constexpr const char* kObjectsBenchTargets =
    "targets (issue 42): closed_symmetric coverage >= 97% (truth within 2 mm),\n"
    "added points' p95 <= 2 mm, <= 2% of them > 3 mm; closed_asymmetric and open:\n"
    "<= 2% > 3 mm, coverage not below the fused cloud's; every row: no added point\n"
    "in seen-free space. A claw that cannot hold an object: the row says why, not met.\n";

std::string ObjectsBenchUsage() {
  return std::string(kObjectsBenchOptions) + kSensorOptionsUsage + kObjectsBenchTargets;
}

// The targets.
constexpr double kMinCoverageSymmetric = 0.97;
constexpr double kMaxAddedP95MmSymmetric = 2.0;
constexpr double kMaxWrongShare = 0.02;
// The repair's time target per cloud, with the record [ms].
constexpr double kRepairTargetMs = 100.0;

struct RowSpec {
  const ManifestObject* object;
  synth::ClawType claw;
  synth::GraspWay grasp;
  uint64_t seed;
};

// A target a row missed: the JSON field it concerns and what happened.
struct Miss {
  std::string field;
  std::string text;
};

struct RowResult {
  std::string not_run;  // why the row has no numbers ("" when it ran)
  double opening_mm{0.0};
  bool workspace_grown{false};
  std::string hold_note;  // the placement's liberties (fingers lengthened)
  size_t fused_points{0};
  double fused_coverage{0.0};
  double fused_p99_mm{0.0};
  double fused_p95_mm{0.0};
  double fused_off_share{0.0};  // of the fused points, farther than 3 mm from the truth
  Outcome repaired;
  std::vector<Miss> misses;
  /// The case proposed beside the targets: the same targets, with the
  /// added points' p95 and wrong share taken over those the repair stands
  /// behind (confidence > 0.5). A lid no view saw, at 0.5, then counts for
  /// the coverage and not against the wrong share: right for a can and
  /// for a cup alike (docs/repair-method.md).
  std::vector<Miss> misses_on_trusted;
  bool meets() const { return misses.empty(); }
  bool meets_on_trusted() const { return not_run.empty() && misses_on_trusted.empty(); }
};

std::vector<std::string> SplitList(const std::string& option, const std::string& text) {
  std::vector<std::string> items;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    if (item.empty()) throw UsageError(option + " '" + text + "': an empty item");
    if (std::find(items.begin(), items.end(), item) != items.end()) {
      throw UsageError(option + " '" + text + "': '" + item + "' twice");
    }
    items.push_back(item);
  }
  if (items.empty() || text.back() == ',') throw UsageError(option + " '" + text + "': an empty item");
  return items;
}

std::string Format(const char* format, double a, double b = 0.0) {
  char text[128];
  std::snprintf(text, sizeof(text), format, a, b);
  return text;
}

// The targets of `kind` that `o` misses (fused_coverage: the cloud before
// the repair).
std::vector<Miss> MissedTargets(ObjectKind kind, const Outcome& o, double fused_coverage) {
  std::vector<Miss> misses;
  if (kind == ObjectKind::kClosedSymmetric) {
    if (o.coverage < kMinCoverageSymmetric) {
      misses.push_back({"coverage_2mm", Format("coverage %.3f < %.2f", o.coverage, kMinCoverageSymmetric)});
    }
    if (o.added_p95_mm > kMaxAddedP95MmSymmetric) {
      misses.push_back(
          {"added_p95_mm", Format("added p95 %.2f > %.0f mm", o.added_p95_mm, kMaxAddedP95MmSymmetric)});
    }
  } else if (o.coverage < fused_coverage) {
    misses.push_back({"coverage_2mm", Format("coverage %.3f < fused %.3f", o.coverage, fused_coverage)});
  }
  if (o.added_wrong > kMaxWrongShare) {
    misses.push_back({"wrong_share", Format("wrong %.3f > %.2f", o.added_wrong, kMaxWrongShare)});
  }
  if (o.added_in_free > 0) {
    misses.push_back({"seen_free_points", Format("%.0f added in seen-free space", o.added_in_free)});
  }
  return misses;
}

// `o` with the added points' measures taken over the trusted ones.
Outcome OnTrusted(Outcome o) {
  o.added_p95_mm = o.trusted_p95_mm;
  o.added_wrong = o.trusted_wrong;
  return o;
}

std::string MeetsText(const RowResult& r) {
  if (r.meets()) return "yes";
  std::string text = "no:";
  for (size_t i = 0; i < r.misses.size(); ++i) text += (i ? "; " : " ") + r.misses[i].text;
  return text;
}

// Why the scene's claw cannot hold its object, or "": the synthesizer opens
// a built-in claw as wide as the object needs (scene.hpp), past its joint
// limit if it must; a real claw stops there.
std::string HoldProblem(const synth::Scene& scene) {
  const double needed = scene.placement().opening_m;
  const double most = scene.config().claw_config.max_opening_m;
  if (needed > most) {
    return Format("too big for the claw: needs an opening of %.1f mm (finger to axis), it opens to %.1f mm",
                  1000.0 * needed, 1000.0 * most);
  }
  return "";
}

// The pipeline's default box, grown to hold the scene's object (plus 2 cm,
// as `synth` reports it) where it does not: the box is a rig setting, and
// an object cut by it would measure the box, not the repair.
PipelineConfig PipelineFor(const synth::Scene& scene, bool reject_depth_edges, bool* grown) {
  PipelineConfig config;
  config.reject_depth_edges = reject_depth_edges;
  const Eigen::AlignedBox3d need = scene.WorkspaceBoxG(0.02);
  fusion::WorkspaceBox& box = config.workspace;
  *grown = false;
  for (int k = 0; k < 3; ++k) {
    if (k < 2 && need.min()[k] < box.min_G[k]) box.min_G[k] = need.min()[k], *grown = true;
    if (need.max()[k] > box.max_G[k]) box.max_G[k] = need.max()[k], *grown = true;
  }
  return config;
}

std::string DumpName(const RowSpec& s) {
  std::string name = s.object->name;
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  }
  return name + "_" + synth::ClawTypeName(s.claw) + "_" + synth::GraspWayName(s.grasp) + "_s" +
         std::to_string(s.seed);
}

const char* kDumpKinds[] = {"truth", "fused", "repaired"};

std::string DumpPath(const std::string& dir, const RowSpec& s, const char* what) {
  return (std::filesystem::path(dir) / (DumpName(s) + "_" + what + ".ply")).string();
}

// One row: the scene, the pipeline, the repair and the measurements.
// @throws std::exception on a failure of the run itself (not of a target).
RowResult RunRow(const RowSpec& s, const TriangleMesh& mesh, int frames, int repeat,
                 const std::string& dump_dir, const SensorOptions& sensor) {
  RowResult r;
  synth::SceneConfig sc;
  sc.sensor = sensor.sensor;
  sc.mesh = mesh;
  sc.mesh_name = s.object->path;
  sc.claw = s.claw;
  sc.grasp = s.grasp;
  sc.num_frames = frames;
  sc.seed = s.seed;
  std::optional<synth::Scene> scene;
  try {
    scene.emplace(sc);
  } catch (const std::invalid_argument& e) {  // the claw cannot take it
    r.not_run = std::string("not grasped: ") + e.what();
    r.misses.push_back({"grasped", r.not_run});
    return r;
  }
  r.opening_mm = 1000.0 * scene->placement().opening_m;
  r.not_run = HoldProblem(*scene);
  if (!r.not_run.empty()) {
    r.misses.push_back({"grasped", r.not_run});
    return r;
  }
  if (scene->placement().claw.finger_length_m > sc.claw_config.finger_length_m) {
    r.hold_note = Format("fingers lengthened %.0f -> %.0f mm", 1000.0 * sc.claw_config.finger_length_m,
                         1000.0 * scene->placement().claw.finger_length_m);
  }
  const std::unique_ptr<Pipeline> pipeline =
      RunSceneThroughPipeline(*scene, PipelineFor(*scene, sensor.reject_depth_edges, &r.workspace_grown));
  const ObjectCloud fused = pipeline->ExtractCloud();
  const mesh::SurfaceSamples truth = TruthSamples(*scene);
  r.fused_points = fused.size();
  if (fused.size() == 0) {
    r.not_run = "nothing fused";
    r.misses.push_back({"fused_points", r.not_run});
    return r;
  }
  const FusedMeasures measured = MeasureFused(fused, truth.points);
  r.fused_coverage = measured.coverage;
  r.fused_p99_mm = measured.p99_mm;
  r.fused_p95_mm = measured.p95_mm;
  r.fused_off_share = measured.off_object_share;
  const evidence::VisibilityRecord& record = pipeline->visibility();
  const TimedRepair repair = RepairTimed(fused, &record, repeat);
  r.repaired = Measure(repair.cloud, fused.size(), truth.points, record);
  r.repaired.ms = repair.best_ms;
  r.repaired.note = RepairNote(repair.report);
  r.repaired.top_completion = repair.report.top_completion;
  r.repaired.top_confidence = repair.report.top_confidence;
  r.repaired.steps = repair.best_steps;
  r.repaired.evidence = repair.report.evidence;
  r.misses = MissedTargets(s.object->kind, r.repaired, r.fused_coverage);
  r.misses_on_trusted = MissedTargets(s.object->kind, OnTrusted(r.repaired), r.fused_coverage);
  if (!dump_dir.empty()) {
    ObjectCloud truth_cloud;
    truth_cloud.points_G = truth.points;
    truth_cloud.normals_G = truth.normals;
    io::WriteCloudPly(DumpPath(dump_dir, s, "truth"), truth_cloud);
    io::WriteCloudPly(DumpPath(dump_dir, s, "fused"), fused);
    io::WriteCloudPly(DumpPath(dump_dir, s, "repaired"), repair.cloud);
  }
  return r;
}

// A row that did not run has no numbers: null, not 0.
template <typename Number>
nlohmann::ordered_json NumberOrNull(bool ran, Number value) {
  return ran ? nlohmann::ordered_json(value) : nlohmann::ordered_json(nullptr);
}

nlohmann::ordered_json RowJson(const RowSpec& s, const RowResult& r) {
  const bool ran = r.not_run.empty();
  nlohmann::ordered_json failed = nlohmann::ordered_json::array();
  for (const Miss& m : r.misses) failed.push_back({{"field", m.field}, {"text", m.text}});
  nlohmann::ordered_json row = {
      {"object", s.object->name},
      {"kind", ObjectKindName(s.object->kind)},
      {"split", ObjectSplitName(s.object->split)},
      {"claw", synth::ClawTypeName(s.claw)},
      {"grasp", synth::GraspWayName(s.grasp)},
      {"seed", s.seed},
      {"ran", ran},
      {"reason", r.not_run},
      {"opening_mm", r.opening_mm},
      {"workspace_grown", r.workspace_grown},
      {"fused_points", r.fused_points},
      {"fused_coverage", NumberOrNull(ran, r.fused_coverage)},
      {"fused_p99_mm", NumberOrNull(ran, r.fused_p99_mm)},
      {"fused_p95_mm", NumberOrNull(ran, r.fused_p95_mm)},
      {"fused_off_object_share", NumberOrNull(ran, r.fused_off_share)},
      {"points", NumberOrNull(ran, r.repaired.points)},
      {"added", NumberOrNull(ran, r.repaired.added)},
      {"coverage_2mm", NumberOrNull(ran, r.repaired.coverage)},
      {"added_p95_mm", NumberOrNull(ran, r.repaired.added_p95_mm)},
      {"wrong_share", NumberOrNull(ran, r.repaired.added_wrong)},
      {"trusted_added", NumberOrNull(ran, r.repaired.trusted_added)},
      {"trusted_p95_mm", NumberOrNull(ran, r.repaired.trusted_p95_mm)},
      {"trusted_wrong_share", NumberOrNull(ran, r.repaired.trusted_wrong)},
      {"seen_free_points", NumberOrNull(ran, r.repaired.added_in_free)},
      {"truth_outside_bound",
       NumberOrNull(ran && std::isfinite(r.repaired.truth_outside_bound), r.repaired.truth_outside_bound)},
      {"repair_ms", NumberOrNull(ran, r.repaired.ms)},
      {"meets", r.meets()},
      {"failed", failed},
      {"meets_on_trusted", r.meets_on_trusted()},
      {"note", ran ? r.repaired.note : r.not_run},
  };
  if (!r.hold_note.empty()) row["hold_note"] = r.hold_note;
  if (ran) {
    row["top_completion"] = r.repaired.top_completion;
    row["top_confidence"] = r.repaired.top_confidence;
    row["steps_ms"] = StepsJson(r.repaired.steps);
  }
  return row;
}

// Rows meeting their targets / rows, for one group.
struct Tally {
  int rows{0};
  int met{0};
  void Add(bool meets) { ++rows, met += meets; }
};

// Per object: the tally, the fused p99 and the repair time over its rows.
struct ObjectTally {
  Tally tally;
  std::vector<double> fused_p99_mm;
  std::vector<double> repair_ms;
  std::vector<double> outside_bound;  ///< truth outside the safe bound, per row that has one
};

double Median(const std::vector<double>& v) { return v.empty() ? 0.0 : Percentile(v, 50.0); }
double Max(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); }

struct Summary {
  Tally all;
  std::map<std::pair<ObjectSplit, ObjectKind>, Tally> on_trusted;  // the proposed case
  std::map<ObjectKind, Tally> by_kind;
  std::map<ObjectSplit, Tally> by_split;
  std::map<std::pair<ObjectSplit, ObjectKind>, Tally> by_split_kind;
  std::vector<std::string> object_order;
  std::map<std::string, ObjectTally> by_object;
  std::vector<double> repair_ms;
  int workspace_grown{0};  // rows run with the pipeline's box grown
  int fingers_lengthened{0};

  void Add(const RowSpec& s, const RowResult& r) {
    workspace_grown += r.workspace_grown;
    fingers_lengthened += !r.hold_note.empty();
    all.Add(r.meets());
    by_kind[s.object->kind].Add(r.meets());
    by_split[s.object->split].Add(r.meets());
    by_split_kind[{s.object->split, s.object->kind}].Add(r.meets());
    on_trusted[{s.object->split, s.object->kind}].Add(r.meets_on_trusted());
    if (!by_object.count(s.object->name)) object_order.push_back(s.object->name);
    ObjectTally& o = by_object[s.object->name];
    o.tally.Add(r.meets());
    if (r.not_run.empty()) {
      o.fused_p99_mm.push_back(r.fused_p99_mm);
      o.repair_ms.push_back(r.repaired.ms);
      repair_ms.push_back(r.repaired.ms);
      if (std::isfinite(r.repaired.truth_outside_bound))
        o.outside_bound.push_back(r.repaired.truth_outside_bound);
    }
  }

  int OverTarget() const {
    return static_cast<int>(
        std::count_if(repair_ms.begin(), repair_ms.end(), [](double ms) { return ms > kRepairTargetMs; }));
  }
};

nlohmann::ordered_json TallyJson(const Tally& t) { return {{"rows", t.rows}, {"met", t.met}}; }

nlohmann::ordered_json SummaryJson(const Summary& s) {
  nlohmann::ordered_json by_kind = nlohmann::ordered_json::object();
  for (const auto& [kind, t] : s.by_kind) by_kind[ObjectKindName(kind)] = TallyJson(t);
  nlohmann::ordered_json by_split = nlohmann::ordered_json::object();
  for (const auto& [split, t] : s.by_split) by_split[ObjectSplitName(split)] = TallyJson(t);
  nlohmann::ordered_json by_split_kind = nlohmann::ordered_json::object();
  for (const auto& [key, t] : s.by_split_kind) {
    by_split_kind[ObjectSplitName(key.first)][ObjectKindName(key.second)] = TallyJson(t);
  }
  nlohmann::ordered_json on_trusted = nlohmann::ordered_json::object();
  for (const auto& [key, t] : s.on_trusted) {
    on_trusted[ObjectSplitName(key.first)][ObjectKindName(key.second)] = TallyJson(t);
  }
  nlohmann::ordered_json by_object = nlohmann::ordered_json::object();
  for (const std::string& name : s.object_order) {
    const ObjectTally& o = s.by_object.at(name);
    by_object[name] = {{"rows", o.tally.rows},
                       {"met", o.tally.met},
                       {"fused_p99_mm_median", Median(o.fused_p99_mm)},
                       {"fused_p99_mm_max", Max(o.fused_p99_mm)},
                       {"repair_ms_max", Max(o.repair_ms)},
                       {"truth_outside_bound_max", Max(o.outside_bound)}};
  }
  return {{"all", TallyJson(s.all)},
          {"by_kind", by_kind},
          {"by_split", by_split},
          {"by_split_kind", by_split_kind},
          {"on_trusted_by_split_kind", on_trusted},
          {"by_object", by_object},
          {"repair_ms",
           {{"median", Median(s.repair_ms)},
            {"max", Max(s.repair_ms)},
            {"over_target", s.OverTarget()},
            {"target_ms", kRepairTargetMs}}},
          {"workspace_grown_rows", s.workspace_grown},
          {"fingers_lengthened_rows", s.fingers_lengthened}};
}

void PrintSummary(const Summary& s) {
  auto line = [](const std::string& label, const Tally& t) {
    std::printf("  %-32s %4d / %-4d (%3.0f%%)\n", label.c_str(), t.met, t.rows,
                t.rows ? 100.0 * t.met / t.rows : 0.0);
  };
  std::printf("\nRows meeting their kind's targets / rows\n");
  for (const auto& [key, t] : s.by_split_kind)
    line(ObjectSplitName(key.first) + ", " + ObjectKindName(key.second), t);
  for (const auto& [split, t] : s.by_split) line(ObjectSplitName(split), t);
  for (const auto& [kind, t] : s.by_kind) line(ObjectKindName(kind), t);
  line("all", s.all);
  std::printf(
      "\nThe case proposed beside them: the same targets, the added points' p95 and wrong share taken "
      "over those with confidence > 0.5 (those the repair stands behind); rows meeting it / rows\n");
  for (const auto& [key, t] : s.on_trusted)
    line(ObjectSplitName(key.first) + ", " + ObjectKindName(key.second), t);
  std::printf(
      "\nPer object: met / rows, fused cloud's p99 to the truth [mm] median and max, "
      "repair max [ms], the truth's largest share outside the safe bound\n");
  for (const std::string& name : s.object_order) {
    const ObjectTally& o = s.by_object.at(name);
    std::printf("  %-25s %3d / %-3d  p99 %5.2f %5.2f  %6.1f  %.4f\n", name.c_str(), o.tally.met, o.tally.rows,
                Median(o.fused_p99_mm), Max(o.fused_p99_mm), Max(o.repair_ms), Max(o.outside_bound));
  }
  std::printf(
      "\nRepair with the record, fastest of the repeats, one core: median %.1f ms, max %.1f ms, "
      "%d of %zu clouds over %.0f ms\n",
      Median(s.repair_ms), Max(s.repair_ms), s.OverTarget(), s.repair_ms.size(), kRepairTargetMs);
  if (s.workspace_grown > 0 || s.fingers_lengthened > 0) {
    std::printf(
        "The placement's liberties (--verbose names them per row): %d rows with the pipeline's "
        "workspace box grown to hold the object, %d with the claw's fingers lengthened to reach "
        "the grasp's height\n",
        s.workspace_grown, s.fingers_lengthened);
  }
}

struct Options {
  std::string dir;
  std::vector<std::string> objects;  // --object (all when empty)
  std::optional<ObjectSplit> split;
  std::vector<synth::ClawType> claws{synth::ClawType::kThreeFinger, synth::ClawType::kParallel};
  std::vector<synth::GraspWay> grasps{synth::GraspWay::kTopStraight, synth::GraspWay::kMiddleStraight,
                                      synth::GraspWay::kTopOblique};
  std::vector<uint64_t> seeds{1, 2, 3};
  int frames{90};  // the zoo's: one turn
  int repeat{3};
  std::string dump_dir;
  bool json{false};
  bool verbose{false};
  SensorOptions sensor;  // the artefacts asked for, and the depth-edge rule
};

// @throws UsageError
Options Parse(const Args& args) {
  Options o;
  bool dir_given = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) throw UsageError(a + " needs a value");
      return args[++i];
    };
    if (a == "--objects")
      o.dir = value(), dir_given = true;
    else if (a == "--object")
      o.objects = SplitList(a, value());
    else if (a == "--split") {
      const std::string v = value();
      o.split = ParseObjectSplit(v);
      if (!o.split) throw UsageError("--split '" + v + "': expected tune or check");
    } else if (a == "--claw") {
      o.claws.clear();
      for (const std::string& item : SplitList(a, value())) {
        const auto claw = synth::ParseClawType(item);
        if (!claw) throw UsageError("--claw '" + item + "': expected three-finger or parallel");
        o.claws.push_back(*claw);
      }
    } else if (a == "--grasp") {
      o.grasps.clear();
      for (const std::string& item : SplitList(a, value())) {
        const auto grasp = synth::ParseGraspWay(item);
        if (!grasp) {
          throw UsageError("--grasp '" + item + "': expected top-straight, middle-straight or top-oblique");
        }
        o.grasps.push_back(*grasp);
      }
    } else if (a == "--seeds") {
      o.seeds.clear();
      for (const std::string& item : SplitList(a, value())) {
        o.seeds.push_back(ParseInteger<uint64_t>(a, item, 0, std::numeric_limits<uint64_t>::max()));
      }
    } else if (a == "--frames")
      o.frames = ParseInteger<int>(a, value(), 10, 3000);
    else if (a == "--repeat")
      o.repeat = ParseInteger<int>(a, value(), 1, 100);
    else if (a == "--dump")
      o.dump_dir = value();
    else if (a == "--json")
      o.json = true;
    else if (a == "--verbose")
      o.verbose = true;
    else if (!ParseSensorOption(a, value, &o.sensor))
      throw BadOption(a, ObjectsBenchUsage());
  }
  if (!dir_given || o.dir.empty()) throw UsageError("--objects needs a folder with objects.json");
  return o;
}

}  // namespace

int RunBenchRepairObjects(const Args& args) {
  if (std::find(args.begin(), args.end(), "--help") != args.end() ||
      std::find(args.begin(), args.end(), "-h") != args.end()) {
    std::fputs(ObjectsBenchUsage().c_str(), stdout);
    return 0;
  }
  Options o;
  try {
    o = Parse(args);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "%s: %s\n", kObjectsBenchCommand, e.what());
    return 2;
  }
  // The set: every listed mesh there, the selected ones read (a bad file
  // is refused before any work).
  std::vector<ManifestObject> manifest;
  try {
    manifest = ReadObjectManifest(o.dir);
  } catch (const ManifestError& e) {
    std::fprintf(stderr, "%s: %s\n", kObjectsBenchCommand, e.what());
    return 2;
  }
  for (const std::string& name : o.objects) {
    if (std::none_of(manifest.begin(), manifest.end(),
                     [&](const ManifestObject& m) { return m.name == name; })) {
      std::fprintf(stderr, "%s: --object '%s': not in %s\n", kObjectsBenchCommand, name.c_str(),
                   ManifestPath(o.dir).c_str());
      return 2;
    }
  }
  std::vector<const ManifestObject*> selected;
  std::map<std::string, TriangleMesh> meshes;
  for (const ManifestObject& m : manifest) {
    if (!o.objects.empty() && std::find(o.objects.begin(), o.objects.end(), m.name) == o.objects.end())
      continue;
    if (o.split && m.split != *o.split) continue;
    try {
      meshes[m.name] = ReadObjectMesh(m.path, m.mesh_scale, m.mesh_y_up);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s: object '%s' in %s: %s\n", kObjectsBenchCommand, m.name.c_str(),
                   ManifestPath(o.dir).c_str(), ErrorText(e).c_str());
      return 2;
    }
    const double extent_m = mesh::Bounds(meshes[m.name]).sizes().maxCoeff();
    if (!(extent_m <= kMaxObjectExtentM)) {
      std::fprintf(stderr,
                   "%s: object '%s' in %s: mesh '%s' is %.3g m across; graspfill expects meters and "
                   "objects a claw can hold (\"mesh_scale\": 0.001 for a mesh in mm)\n",
                   kObjectsBenchCommand, m.name.c_str(), ManifestPath(o.dir).c_str(), m.path.c_str(),
                   extent_m);
      return 2;
    }
    selected.push_back(&m);
  }
  if (selected.empty()) {
    std::fprintf(stderr, "%s: no object of %s is in split '%s'\n", kObjectsBenchCommand,
                 ManifestPath(o.dir).c_str(), ObjectSplitName(*o.split).c_str());
    return 2;
  }
  std::vector<RowSpec> specs;
  for (const ManifestObject* m : selected) {
    for (synth::ClawType claw : o.claws) {
      for (synth::GraspWay grasp : o.grasps) {
        for (uint64_t seed : o.seeds) specs.push_back({m, claw, grasp, seed});
      }
    }
  }
  if (!o.dump_dir.empty()) {
    std::vector<std::string> paths;
    for (const RowSpec& s : specs) {
      for (const char* what : kDumpKinds) paths.push_back(DumpPath(o.dump_dir, s, what));
    }
    const std::set<std::string> distinct(paths.begin(), paths.end());
    std::string problem = CheckDumpPaths(o.dump_dir, paths);
    if (problem.empty() && distinct.size() != paths.size()) {
      problem =
          "two objects' names give the same --dump file names (letters, digits, '-', '_', '.' are kept)";
    }
    if (!problem.empty()) {
      std::fprintf(stderr, "%s: %s\n", kObjectsBenchCommand, problem.c_str());
      return 1;
    }
  }

  if (!o.json) {
    std::printf(
        "Objects of %s through the pipeline (%d frames, one turn%s), repaired with the record:\n"
        "fused: its points, coverage (truth within 2 mm) and p99 distance to the truth;\n"
        "repaired: points, coverage, added points' p95 / share > 3 mm / in seen-free space, "
        "repair ms (fastest of %d)\n\n",
        ManifestPath(o.dir).c_str(), o.frames, SensorOptionsText(o.sensor).c_str(), o.repeat);
    std::printf("%-25s %-17s %-5s %-12s %-15s %4s | %6s %6s %6s | %6s %6s %6s %6s %5s %6s | %s\n", "object",
                "kind", "split", "claw", "grasp", "seed", "fused", "cov", "p99mm", "points", "cov", "p95mm",
                "wrong", "free", "ms", "meets");
  }
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  Summary summary;
  ProgressLine progress("bench repair --objects", "rows", static_cast<int64_t>(specs.size()));
  for (size_t done = 0; done < specs.size(); ++done) {
    const RowSpec& s = specs[done];
    progress.Update(static_cast<int64_t>(done));
    RowResult r;
    try {
      r = RunRow(s, meshes.at(s.object->name), o.frames, o.repeat, o.dump_dir, o.sensor);
    } catch (const std::exception& e) {
      progress.Clear();
      std::fprintf(stderr, "%s: %s, %s, %s, seed %llu: %s\n", kObjectsBenchCommand, s.object->name.c_str(),
                   synth::ClawTypeName(s.claw).c_str(), synth::GraspWayName(s.grasp).c_str(),
                   static_cast<unsigned long long>(s.seed), ErrorText(e).c_str());
      return 1;
    }
    summary.Add(s, r);
    if (o.json) {
      rows.push_back(RowJson(s, r));
      continue;
    }
    progress.Clear();  // the row on a line of its own
    std::printf("%-25s %-17s %-5s %-12s %-15s %4llu |", s.object->name.c_str(),
                ObjectKindName(s.object->kind).c_str(), ObjectSplitName(s.object->split).c_str(),
                synth::ClawTypeName(s.claw).c_str(), synth::GraspWayName(s.grasp).c_str(),
                static_cast<unsigned long long>(s.seed));
    if (r.not_run.empty()) {
      const Outcome& x = r.repaired;
      std::printf(" %6zu %6.3f %6.2f | %6zu %6.3f %6.2f %6.3f %5d %6.1f | %s\n", r.fused_points,
                  r.fused_coverage, r.fused_p99_mm, x.points, x.coverage, x.added_p95_mm, x.added_wrong,
                  x.added_in_free, x.ms, MeetsText(r).c_str());
    } else {
      std::printf(" %6zu %6s %6s | %6s %6s %6s %6s %5s %6s | %s\n", r.fused_points, "-", "-", "-", "-", "-",
                  "-", "-", "-", MeetsText(r).c_str());
    }
    if (o.verbose && r.not_run.empty()) {
      std::printf(
          "    %s%s%s; truth outside the safe bound: %.4f; added with confidence > 0.5: %zu, p95 %.2f mm, "
          "wrong %.3f, the proposed case %s\n"
          "      ms:%s\n",
          r.repaired.note.c_str(), r.workspace_grown ? "; workspace box grown to hold the object" : "",
          r.hold_note.empty() ? "" : ("; " + r.hold_note).c_str(), r.repaired.truth_outside_bound,
          r.repaired.trusted_added, r.repaired.trusted_p95_mm, r.repaired.trusted_wrong,
          r.meets_on_trusted() ? "met" : "not met", StepsText(r.repaired.steps).c_str());
    }
    std::fflush(stdout);
  }
  progress.Clear();
  if (o.json) {
    nlohmann::ordered_json seeds = nlohmann::ordered_json::array();
    for (uint64_t seed : o.seeds) seeds.push_back(seed);
    const nlohmann::ordered_json out = {{"objects", ManifestPath(o.dir)},
                                        {"frames", o.frames},
                                        {"seeds", seeds},
                                        {"rows", rows},
                                        {"summary", SummaryJson(summary)}};
    std::printf("%s\n", out.dump(2).c_str());
  } else {
    PrintSummary(summary);
  }
  return 0;
}

}  // namespace graspfill::cli
