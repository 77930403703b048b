// SPDX-License-Identifier: BSD-3-Clause
// graspfill bench [LOG]: per-frame cost of graspfill's frame path (crop, claw
// cut-out, integration, visibility record, pose refinement) side by side, in
// the same run, with Open3D integrating the very frames the pipeline fused
// (cropped and masked) and nothing else: the path's overhead over the
// integration it cannot avoid. Then replay throughput (log decoding + the
// whole pipeline) in frames per second.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_integrators.hpp"
#include "claw_option.hpp"
#include "commands.hpp"
#include "data_paths.hpp"
#include "graspfill/core/pose_interpolation.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/pipeline/pipeline.hpp"
#include "module/process_memory.hpp"
#include "module/sequencer_feed.hpp"
#include "module/session_loop.hpp"
#include "number_parsing.hpp"
#include "progress.hpp"
#include "sources/lcm_log_source.hpp"
#include "sources/prefetching_source.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {
namespace {

std::string BenchUsage() {
  return "usage: graspfill bench [LOG] [--claw SPEC] [--repeat N] [--two-threads] [--json]\n"
         "  LOG defaults to the bundled recording " +
         (DataDir() / "replay" / "default" / "recording.lcmlog").string() +
         "\n"
         "  --repeat N   replay passes for the throughput figure (default 3; the best is kept)\n"
         "  --two-threads  also time Open3D's integrators at 2 OpenMP threads (on busy cores\n"
         "               the legacy volume's team waits at every block: minutes, not seconds)\n"
         "The reference: Open3D's TSDF integration of the frames the pipeline fused, as it\n"
         "fused them (cropped, the claw cut out, at the refined pose), with nothing else:\n"
         "its legacy ScalableTSDFVolume (the product's) beside its tensor VoxelBlockGrid, at\n"
         "16^3 and 8^3 voxels a block, and their final clouds compared (with gt_cloud.ply\n"
         "beside LOG, against the truth too).\n";
}

using Clock = std::chrono::steady_clock;
double Ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

// The progress of all of the bench's passes over the frames.
struct FramesDone {
  ProgressLine& line;
  int64_t done{0};
  void Add(int64_t n = 1) { line.Update(done += n); }
};

struct PosedFrame {
  DepthFrame frame;
  GripperState state;
};

// Every depth frame of the log with its interpolated gripper state.
std::vector<PosedFrame> LoadPosedFrames(const std::string& path) {
  rt::LcmLogSource::Config config;
  config.path = path;
  rt::LcmLogSource source(config);
  std::vector<DepthFrame> frames;
  GripperStateBuffer states(1 << 16, 50000);
  rt::SourceEvent event;
  for (rt::FrameResult r; (r = source.Next(&event)) != rt::FrameResult::kEndOfStream;) {
    if (r != rt::FrameResult::kOk) throw std::runtime_error("bad event: " + event.error);
    if (event.kind == rt::SourceEvent::Kind::kDepth)
      frames.push_back(event.depth);
    else
      states.Push(event.gripper);
  }
  std::vector<PosedFrame> posed;
  for (DepthFrame& f : frames) {
    PosedFrame p;
    if (states.Lookup(f.utime, &p.state) != PoseLookup::kOk) continue;
    p.frame = std::move(f);
    posed.push_back(std::move(p));
  }
  if (posed.empty()) throw std::runtime_error("no posed depth frames in '" + path + "'");
  return posed;
}

// Feeds every posed frame, its gripper state first, to the pipeline.
void FeedFrames(const std::vector<PosedFrame>& frames, Pipeline* pipeline, FramesDone* progress) {
  for (const PosedFrame& p : frames) {
    pipeline->AddGripperState(p.state);
    pipeline->AddDepthFrame(p.frame);
    progress->Add();
  }
}

// Open3D's integration alone, on the frames `pipeline` fuses as it fuses
// them: each one, right after the pipeline took it, integrated into
// volumes of the same settings and timed, Open3D's legacy volume (the
// product's) and its tensor VoxelBlockGrid (bench_integrators.hpp), at one
// thread (the product's default) and, with --two-threads, at two. A call
// that fused more than one frame (a frame kept pending) leaves the
// reference its last one only.
struct Open3dReference {
  IntegratorComparison one_thread;
  std::unique_ptr<IntegratorComparison> two_threads;  // with --two-threads
  int64_t fused_seen{0};
  int64_t frames_missed{0};

  Open3dReference(const PipelineConfig& config, bool also_two_threads) : one_thread(config.tsdf, 1) {
    if (also_two_threads) two_threads = std::make_unique<IntegratorComparison>(config.tsdf, 2);
  }
  void AfterCall(const Pipeline& pipeline) {
    const int64_t fused = pipeline.stats().frames_integrated;
    if (fused == fused_seen) return;
    frames_missed += fused - fused_seen - 1;
    fused_seen = fused;
    one_thread.Integrate(pipeline.last_fused_frame(), pipeline.last_fused_T_C_V());
    if (two_threads) two_threads->Integrate(pipeline.last_fused_frame(), pipeline.last_fused_T_C_V());
  }
  // The product's volume at one thread: the "open3d alone" column.
  const StageTotal& integrate() const { return one_thread.runs()[0].integrate; }
};

// FeedFrames with the reference taking each fused frame.
void FeedFramesWithReference(const std::vector<PosedFrame>& frames, Pipeline* pipeline,
                             Open3dReference* reference, FramesDone* progress) {
  for (const PosedFrame& p : frames) {
    pipeline->AddGripperState(p.state);
    reference->AfterCall(*pipeline);
    pipeline->AddDepthFrame(p.frame);
    reference->AfterCall(*pipeline);
    progress->Add();
  }
}

// The frame path on the same frames with pose refinement off (its stages
// only: every frame fused at its logged pose).
double FramePathWithoutRefinementMs(PipelineConfig config, const claw::ClawModel& claw,
                                    const std::vector<PosedFrame>& frames, FramesDone* progress) {
  config.refine.enabled = false;
  Pipeline pipeline(config, claw);
  FeedFrames(frames, &pipeline, progress);
  const PipelineStats& s = pipeline.stats();
  return s.depth_edges.mean_ms() + s.crop.mean_ms() + s.mask.mean_ms() + s.integrate.mean_ms() +
         s.visibility.mean_ms();
}

// The frame path on the same frames with object tracking on (refine/
// object_tracker.hpp; its model updates included in its stage).
PipelineStats FramePathWithTracking(PipelineConfig config, const claw::ClawModel& claw,
                                    const std::vector<PosedFrame>& frames, FramesDone* progress) {
  config.track_object.enabled = true;
  Pipeline pipeline(config, claw);
  FeedFrames(frames, &pipeline, progress);
  return pipeline.stats();
}

// The same frames with their depth `scale` times too long (an uncalibrated
// sensor): the refinement finds the scale from the claw and, once it is
// confident, the frames are divided by it (depth_rescale's cost). The
// estimate needs refine::kDepthScaleMinFrames fused frames: a recording
// with fewer is played again, turn after turn, each turn's stamps after
// the last one's, until it has that many and a quarter more.
struct DepthErrorPass {
  PipelineStats stats;
  refine::DepthScaleEstimate found;
  int turns{0};
};
// The turns of a recording of `frames` posed frames that the pass plays.
int DepthErrorTurns(size_t frames) {
  const size_t wanted = static_cast<size_t>(refine::kDepthScaleMinFrames) * 5 / 4;
  return static_cast<int>((wanted + frames - 1) / frames);
}
DepthErrorPass WithDepthError(const PipelineConfig& config, const claw::ClawModel& claw,
                              std::vector<PosedFrame> frames, float scale, FramesDone* progress) {
  const int turns = DepthErrorTurns(frames.size());
  constexpr int64_t kFrameAt30HzUs = 33333;  // a lone frame's period
  const int64_t span_us = frames.back().frame.utime - frames.front().frame.utime;
  const int64_t turn_us =
      span_us + (frames.size() > 1 ? span_us / static_cast<int64_t>(frames.size() - 1) : kFrameAt30HzUs);
  for (PosedFrame& p : frames) {
    for (float& z : p.frame.depth_m) z *= scale;
  }
  Pipeline pipeline(config, claw);
  for (int t = 0; t < turns; ++t) {
    if (t > 0) {
      for (PosedFrame& p : frames) p.frame.utime += turn_us, p.state.utime += turn_us;
    }
    FeedFrames(frames, &pipeline, progress);
  }
  return {pipeline.stats(), pipeline.refiner().depth_scale(), turns};
}

// Extraction as the live loop does it, a cloud every `every` fused frames:
// the cached extraction (only the volume units changed since the last one,
// and their neighbours, anew) beside Open3D's over the whole volume, on the
// same volume each time [ms]; and the share of units extracted anew.
struct ExtractionTimes {
  std::vector<double> cached_ms, full_ms;
  double units_share{0.0};
  int clouds{0};
};
ExtractionTimes ExtractionEvery(const PipelineConfig& config, const claw::ClawModel& claw,
                                const std::vector<PosedFrame>& frames, int every, FramesDone* progress) {
  Pipeline pipeline(config, claw);
  ExtractionTimes t;
  int64_t units = 0, anew = 0, fused = 0;
  ObjectCloud cloud;
  for (const PosedFrame& p : frames) {
    pipeline.AddGripperState(p.state);
    pipeline.AddDepthFrame(p.frame);
    progress->Add();
    if (pipeline.stats().frames_integrated == fused) continue;
    fused = pipeline.stats().frames_integrated;
    if (fused % every != 0) continue;
    const auto t0 = std::chrono::steady_clock::now();
    pipeline.fusion().ExtractCloud(&cloud);
    const auto t1 = std::chrono::steady_clock::now();
    pipeline.fusion().ExtractCloudUncached(&cloud);
    const auto t2 = std::chrono::steady_clock::now();
    t.cached_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    t.full_ms.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
    units += pipeline.fusion().units();
    anew += pipeline.fusion().units_extracted();
    ++t.clouds;
  }
  t.units_share = units > 0 ? static_cast<double>(anew) / static_cast<double>(units) : 0.0;
  return t;
}

// a / b, 0 when b is 0 (nothing measured).
double Ratio(double a, double b) { return b > 0.0 ? a / b : 0.0; }

double FramePathMs(const PipelineStats& s) {
  return s.depth_edges.mean_ms() + s.crop.mean_ms() + s.mask.mean_ms() + s.integrate.mean_ms() +
         s.visibility.mean_ms() + s.refine_time.mean_ms() + s.depth_scale.mean_ms() +
         s.depth_rescale.mean_ms() + s.track_time.mean_ms();
}

// Replays the log file through a fresh pipeline: decode + pipeline, no output.
double ReplayFps(const std::string& path, const claw::ClawModel& claw, int64_t* frames,
                 FramesDone* progress) {
  const Clock::time_point start = Clock::now();
  rt::LcmLogSource::Config config;
  config.path = path;
  rt::PrefetchingSource source(std::make_unique<rt::LcmLogSource>(config));  // as replay does
  // The session loop replay and live run, bad events skipped.
  rt::SequencerFeed feed(
      [&](const std::optional<io::SessionDescription>&) {
        return std::make_unique<rt::GraspSequencer>(PipelineConfig{}, claw, rt::GraspSequencerConfig{},
                                                    nullptr);
      },
      /*skip_bad=*/true);
  rt::SessionLoopLimits limits;
  const int64_t done_before = progress->done;
  limits.on_tick = [&] { progress->line.Update(done_before + feed.depth_events()); };
  limits.tick_ms = 200;
  rt::SessionLoop(limits).Run(&source, &feed);
  progress->Add(feed.depth_events());
  if (feed.sequencer() == nullptr) return 0.0;
  feed.sequencer()->Flush();
  *frames = feed.sequencer()->stats().frames_integrated;
  return *frames / (Ms(Clock::now() - start) / 1000.0);
}

struct BenchOptions {
  std::string log;  // the bundled recording unless given
  std::string claw_spec{"three-finger"};
  int repeat{3};
  bool json{false};
  bool two_threads{false};  // the integrators at 2 OpenMP threads too
};

// The object's surface the recording was made of (gt_cloud.ply beside
// the log, as `graspfill synth` writes it), if there.
std::optional<ObjectCloud> TruthBesideLog(const std::string& log) {
  const std::filesystem::path path = std::filesystem::path(log).parent_path() / "gt_cloud.ply";
  if (!std::filesystem::exists(path)) return std::nullopt;
  return io::ReadCloudPly(path.string());
}

// Reads the command line into *o. Returns -1 to go on, else the exit code:
// 0 after --help, 2 after a bad option or value (said on stderr).
int ParseBenchArgs(const Args& args, BenchOptions* o) {
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--help" || args[i] == "-h") {
      std::fputs(BenchUsage().c_str(), stdout);
      return 0;
    } else if (args[i] == "--json") {
      o->json = true;
    } else if (args[i] == "--two-threads") {
      o->two_threads = true;
    } else if ((args[i] == "--claw" || args[i] == "--repeat") && i + 1 < args.size()) {
      try {
        if (args[i] == "--claw")
          o->claw_spec = ResolveClawSpec(args[++i], InstalledClawsDir());
        else
          o->repeat = ParseInteger<int>("--repeat", args[++i], 1, 1000);
      } catch (const UsageError& e) {
        std::fprintf(stderr, "graspfill bench: %s\n", e.what());
        return 2;
      }
    } else if (!args[i].empty() && args[i][0] != '-') {
      o->log = args[i];
    } else {
      std::fprintf(stderr, "graspfill bench: %s\n%s", BadOptionText(args[i], BenchUsage()).c_str(),
                   BenchUsage().c_str());
      return 2;
    }
  }
  if (o->log.empty()) o->log = (BundledRecordingDir() / "recording.lcmlog").string();
  return -1;
}

// The depth error of the pass that times the depth's rescaling.
constexpr float kBenchDepthError = 1.01f;

// What the bench measured, for the table or the JSON.
struct BenchResults {
  size_t frames{0};
  PipelineStats stats;  // graspfill's frame path, refinement on
  double cut_ms{0.0};   // depth edges + crop + claw cut-out
  double total_ms{0.0};
  double unrefined_total_ms{0.0};
  size_t points{0};
  PipelineStats tracked;  // with --track-object
  PipelineStats scaled;   // the depth 1% long
  refine::DepthScaleEstimate scale_found;
  int scale_turns{0};  // turns of the recording the 1%-long pass played
  ExtractionTimes extraction;
  double raster_mask_ms{0.0};
  double depth_edges_ms{0.0};  // the depth-edge rejection, off by default, timed on
  double depth_edge_pixels_per_frame{0.0};
  double open3d_integrate_ms{0.0};  // the reference, per frame it took
  IntegratorSummary integrators;    // the reference beside the tensor VoxelBlockGrid
  int64_t open3d_frames{0};
  int64_t open3d_frames_missed{0};
  int64_t replay_frames{0};
  double best_fps{0.0};
  // The frame path once more, last, with the heap readied as `live` readies
  // it (live_session.hpp): no page faults for new blocks and key frames.
  bool heap_readied{false};
  PipelineStats readied;
  double readied_open3d_integrate_ms{0.0};
};

BenchResults MeasureFramePath(const BenchOptions& o, const claw::ClawModel& claw,
                              const std::vector<PosedFrame>& frames) {
  // Refinement on (the default), its cost shown beside the path without.
  PipelineConfig config;
  config.refine.enabled = true;

  // Six passes over the posed frames (the depth error's plays the
  // recording as many turns as its estimate needs), then the replays of
  // the whole log (a log's unposed frames can take the count past the
  // total: capped).
  const int64_t passes = 6 + DepthErrorTurns(frames.size()) + o.repeat;
  ProgressLine line("bench", "frames", static_cast<int64_t>(frames.size()) * passes);
  FramesDone progress{line};
  BenchResults r;
  r.frames = frames.size();

  // graspfill's frame path, stage by stage (the Pipeline's own code path),
  // and the reference on the frames it fused.
  Pipeline pipeline(config, claw);
  Open3dReference reference(config, o.two_threads);
  FeedFramesWithReference(frames, &pipeline, &reference, &progress);
  reference.one_thread.Finish();
  if (reference.two_threads) reference.two_threads->Finish();
  r.open3d_integrate_ms = reference.integrate().mean_ms();
  const std::optional<ObjectCloud> truth = TruthBesideLog(o.log);
  r.integrators = Summarize(reference.one_thread, reference.two_threads.get(), truth ? &*truth : nullptr);
  r.open3d_frames = reference.integrate().count;
  r.open3d_frames_missed = reference.frames_missed;
  const PipelineStats& s = pipeline.stats();
  r.cut_ms = s.depth_edges.mean_ms() + s.crop.mean_ms() + s.mask.mean_ms();
  r.total_ms = FramePathMs(s);  // tracking is off here
  r.unrefined_total_ms = FramePathWithoutRefinementMs(config, claw, frames, &progress);
  r.points = pipeline.ExtractCloud().size();
  r.stats = pipeline.stats();
  r.tracked = FramePathWithTracking(config, claw, frames, &progress);
  r.extraction = ExtractionEvery(config, claw, frames, 3, &progress);
  const DepthErrorPass scaled = WithDepthError(config, claw, frames, kBenchDepthError, &progress);
  r.scaled = scaled.stats;
  r.scale_found = scaled.found;
  r.scale_turns = scaled.turns;

  // The z-buffer alternative to Embree for the claw's depth, same frames.
  // The same pass times the depth-edge rejection (off by default).
  PipelineConfig raster_config = config;
  raster_config.mask.method = claw::ClawMaskMethod::kRaster;
  raster_config.reject_depth_edges = true;
  Pipeline raster(raster_config, claw);
  FeedFrames(frames, &raster, &progress);
  r.raster_mask_ms = raster.stats().mask.mean_ms();
  r.depth_edges_ms = raster.stats().depth_edges.mean_ms();
  r.depth_edge_pixels_per_frame = Ratio(static_cast<double>(raster.stats().depth_edge_pixels),
                                        static_cast<double>(raster.stats().depth_edges.count));

  for (int k = 0; k < o.repeat; ++k) {
    r.best_fps = std::max(r.best_fps, ReplayFps(o.log, claw, &r.replay_frames, &progress));
  }

  // Last, since it is process-wide and for good: the heap readied as
  // `live` readies it, and the frame path again (with its reference).
  r.heap_readied = rt::ReserveHeap(static_cast<size_t>(kLiveHeapReserveMb));
  if (r.heap_readied) {
    Pipeline readied(config, claw);
    Open3dReference readied_reference(config, false);
    FeedFramesWithReference(frames, &readied, &readied_reference, &progress);
    r.readied = readied.stats();
    r.readied_open3d_integrate_ms = readied_reference.integrate().mean_ms();
  }
  line.Clear();
  return r;
}

void PrintBenchJson(const std::string& log, const BenchResults& r) {
  const PipelineStats& s = r.stats;
  const ExtractionTimes& extraction = r.extraction;
  nlohmann::ordered_json j;
  j["log"] = log;
  j["frames"] = r.frames;
  j["graspfill"] = {{"crop_ms", s.crop.mean_ms()},
                    {"mask_ms", s.mask.mean_ms()},
                    {"cutout_ms", r.cut_ms},
                    {"mask_zbuffer_ms", r.raster_mask_ms},
                    {"depth_edges_when_on_ms", r.depth_edges_ms},
                    {"depth_edge_pixels_per_frame_when_on", r.depth_edge_pixels_per_frame},
                    {"integrate_ms", s.integrate.mean_ms()},
                    {"visibility_ms", s.visibility.mean_ms()},
                    {"refine_ms", s.refine_time.mean_ms()},
                    {"depth_scale_ms", s.depth_scale.mean_ms()},
                    {"depth_rescale_when_applied_ms", r.scaled.depth_rescale.mean_ms()},
                    {"frames_rejected_by_refine", s.frames_skipped_refine},
                    {"frame_total_ms", r.total_ms},
                    {"frame_total_without_refine_ms", r.unrefined_total_ms},
                    {"points", r.points},
                    {"track_object_ms", r.tracked.track_time.mean_ms()},
                    {"frames_rejected_by_track_object", r.tracked.frames_skipped_tracking},
                    {"frame_total_with_track_object_ms", FramePathMs(r.tracked)},
                    {"claw_rebuild_ms", s.claw_rebuild.mean_ms()},
                    {"claw_rebuilds", s.claw_rebuild.count}};
  j["open3d_same_frames"] = {{"integrate_ms", r.open3d_integrate_ms},
                             {"frames", r.open3d_frames},
                             {"frames_missed", r.open3d_frames_missed}};
  j["integrators_same_frames"] = IntegratorJson(r.integrators);
  j["visibility_over_integrate"] = Ratio(s.visibility.mean_ms(), s.integrate.mean_ms());
  j["frame_total_over_open3d_integrate"] = Ratio(r.total_ms, r.open3d_integrate_ms);
  j["extraction_every_3_frames"] = {
      {"clouds", extraction.clouds},
      {"cached_ms",
       {{"p50", PercentileOr0(extraction.cached_ms, 50)}, {"p99", PercentileOr0(extraction.cached_ms, 99)}}},
      {"open3d_full_ms",
       {{"p50", PercentileOr0(extraction.full_ms, 50)}, {"p99", PercentileOr0(extraction.full_ms, 99)}}},
      {"units_extracted_share", extraction.units_share}};
  j["depth_1pc_long"] = {
      {"factor_found", r.scale_found.factor},
      {"stderr", std::isfinite(r.scale_found.stderr_) ? nlohmann::ordered_json(r.scale_found.stderr_)
                                                      : nlohmann::ordered_json(nullptr)},
      {"applied", r.scale_found.applied},
      {"turns", r.scale_turns},
      {"frame_total_ms", FramePathMs(r.scaled)}};
  j["replay_fps"] = r.best_fps;
  j["replay_frames"] = r.replay_frames;
  j["heap_readied"] = nullptr;  // the allocator refused the settings
  if (r.heap_readied) {
    j["heap_readied"] = {{"reserve_mb", kLiveHeapReserveMb},
                         {"frame_total_ms", FramePathMs(r.readied)},
                         {"integrate_ms", r.readied.integrate.mean_ms()},
                         {"visibility_ms", r.readied.visibility.mean_ms()},
                         {"open3d_integrate_ms", r.readied_open3d_integrate_ms}};
  }
  std::printf("%s\n", j.dump(2).c_str());
}

void PrintBenchTable(const std::string& log, const BenchResults& r) {
  const PipelineStats& s = r.stats;
  const ExtractionTimes& extraction = r.extraction;
  std::printf("graspfill bench: %s, %zu posed frames\n", log.c_str(), r.frames);
  std::printf("%-34s %12s %14s\n", "per frame [ms]", "graspfill", "open3d alone");
  std::printf("%-34s %12.3f %14s\n", "crop to workspace box", s.crop.mean_ms(), "-");
  std::printf("%-34s %12.3f %14s\n", "claw cut-out (Embree)", s.mask.mean_ms(), "-");
  std::printf("%-34s %12.3f %14s\n", "  (claw cut-out by z-buffer instead)", r.raster_mask_ms, "-");
  std::printf("%-34s %12.3f %14s\n", "  (depth edges rejected, when on)", r.depth_edges_ms, "-");
  std::printf("%-34s %12.3f %14.3f\n", "TSDF integration", s.integrate.mean_ms(), r.open3d_integrate_ms);
  for (size_t i = 1; i < r.integrators.rows.size(); ++i) {
    const std::string label = "  (" + r.integrators.rows[i].name + " instead)";
    std::printf("%-34s %12s %14.3f\n", label.c_str(), "-", r.integrators.rows[i].integrate_ms[0]);
  }
  std::printf("%-34s %12.3f %14s\n", "visibility record (key frames)", s.visibility.mean_ms(), "-");
  std::printf("%-34s %12.3f %14s\n", "pose refinement (claw registration)", s.refine_time.mean_ms(), "-");
  std::printf("%-34s %12.3f %14s\n", "depth scale from the claw", s.depth_scale.mean_ms(), "-");
  std::printf("%-34s %12.3f %14s\n", "  (depth divided by it, when found)", r.scaled.depth_rescale.mean_ms(),
              "-");
  std::printf("%-34s %12.3f %14.3f\n", "frame path total", r.total_ms, r.open3d_integrate_ms);
  std::printf("%-34s %12.3f %14s\n", "  (frame path without refinement)", r.unrefined_total_ms, "-");
  std::printf("%-34s %12.3f %14s\n", "  (object tracking, --track-object)", r.tracked.track_time.mean_ms(),
              "-");
  std::printf("%-34s %12.3f %14s\n", "  (frame path with object tracking)", FramePathMs(r.tracked), "-");
  std::printf("%-34s %12.3f %14s\n", "  (frame path, depth 1% long)", FramePathMs(r.scaled), "-");
  std::printf(
      "the same frames with the depth 1%% long (%d turn%s of them): scale found %.4f +- %.4f, applied %.4f\n",
      r.scale_turns, r.scale_turns == 1 ? "" : "s", r.scale_found.factor, r.scale_found.stderr_,
      r.scale_found.applied);
  std::printf(
      "cloud every 3 fused frames (%d clouds), extraction p50 / p99 [ms]: cached %.2f / %.2f, "
      "Open3D's whole volume %.2f / %.2f (%.0f%% of the units extracted anew)\n",
      extraction.clouds, PercentileOr0(extraction.cached_ms, 50), PercentileOr0(extraction.cached_ms, 99),
      PercentileOr0(extraction.full_ms, 50), PercentileOr0(extraction.full_ms, 99),
      100.0 * extraction.units_share);
  std::printf("open3d alone: the %lld frames the pipeline fused, as it fused them (cropped, claw cut out)",
              static_cast<long long>(r.open3d_frames));
  if (r.open3d_frames_missed > 0) {
    std::printf("; %lld fused in a batch not timed", static_cast<long long>(r.open3d_frames_missed));
  }
  std::printf("\nvisibility record / integration: %.2f\n",
              Ratio(s.visibility.mean_ms(), s.integrate.mean_ms()));
  std::printf("frame path / Open3D's integration alone: %.2f (target: a path of <= 5 ms)\n",
              Ratio(r.total_ms, r.open3d_integrate_ms));
  std::printf("replay throughput (decode + pipeline): %.1f fps over %lld frames (target >= 200)\n",
              r.best_fps, static_cast<long long>(r.replay_frames));
  std::printf(
      "the claw's tables remade when the fingers moved (cut-out, record, refinement): %.2f ms each, "
      "%lld time%s over %zu frames (on that frame's path; not in the per-frame means above, in the "
      "replay's)\n",
      s.claw_rebuild.mean_ms(), static_cast<long long>(s.claw_rebuild.count),
      s.claw_rebuild.count == 1 ? "" : "s", r.frames);
  if (r.heap_readied) {
    std::printf(
        "the heap readied as live readies it (%d MB), measured last: frame path %.3f ms (integration %.3f, "
        "visibility record %.3f), Open3D's integration alone %.3f\n",
        kLiveHeapReserveMb, FramePathMs(r.readied), r.readied.integrate.mean_ms(),
        r.readied.visibility.mean_ms(), r.readied_open3d_integrate_ms);
  } else {
    std::printf("the heap could not be readied as live readies it: no pass with it\n");
  }
  PrintIntegratorTable(r.integrators);
}

}  // namespace

int RunBench(const Args& args) {
  if (!args.empty() && args[0] == "repair") return RunBenchRepair(Args(args.begin() + 1, args.end()));
  if (!args.empty() && args[0] == "live") return RunBenchLive(Args(args.begin() + 1, args.end()));
  BenchOptions o;
  if (const int exit_code = ParseBenchArgs(args, &o); exit_code >= 0) return exit_code;
  const claw::ClawModel claw = MakeClaw(o.claw_spec);
  const std::vector<PosedFrame> frames = LoadPosedFrames(o.log);
  const BenchResults results = MeasureFramePath(o, claw, frames);
  if (o.json) {
    PrintBenchJson(o.log, results);
  } else {
    PrintBenchTable(o.log, results);
  }
  return 0;
}

}  // namespace graspfill::cli
