// SPDX-License-Identifier: BSD-3-Clause
// graspfill oni-record: an OpenNI2 device's depth stream into an .oni file
// through OpenNI2's own recorder (openni::Recorder), e.g. a graspfill-replay
// device to make an .oni of a recording. Reads until the device's stream
// ends (a recording or replay device) or --frames / --duration-s.
#include <chrono>
#include <cstdio>
#include <string>

#include "camera_options.hpp"
#include "commands.hpp"
#include "graspfill/io/output_path.hpp"
#include "number_parsing.hpp"
#include "sources/openni2_source.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {
namespace {

constexpr const char* kOniRecordUsage =
    "usage: graspfill oni-record --device URI -o FILE.oni [options]\n"
    "  --device URI          OpenNI2 device URI (graspfill-replay:LOG.lcmlog, a camera's)\n"
    "  -o FILE.oni           the recording (not overwritten without --force)\n"
    "  --frames N            stop after N frames (default: the end of the stream)\n"
    "  --duration-s S        stop after S seconds (default: none)\n"
    "  --force               overwrite FILE.oni\n"
    "example: graspfill oni-record --device graspfill-replay:rec.lcmlog --frames 300 -o rec.oni\n";

}  // namespace

int RunOniRecord(const Args& args) {
  rt::CameraSource::Config camera;
  camera.device.replay_speed = 0.0f;  // a replay device as fast as recorded
  std::string out;
  bool force = false;
  int64_t max_frames = 0;
  double duration_s = 0.0;
  try {
    for (size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      const bool has_value = i + 1 < args.size();
      if (a == "--help" || a == "-h") {
        std::fputs(kOniRecordUsage, stdout);
        std::fputs(kCameraUsage, stdout);
        return 0;
      } else if (a == "--device" && has_value)
        camera.device.uri = args[++i];
      else if (a == "-o" && has_value)
        out = args[++i];
      else if (a == "--frames" && has_value)
        max_frames = ParseInteger<int64_t>(a, args[++i], 1, 100000000);
      else if (a == "--duration-s" && has_value)
        duration_s = ParseDouble(a, args[++i], 0.0, 7 * 24 * 3600.0, "s");
      else if (a == "--force")
        force = true;
      else if (a != "--gripper-log" && ParseCameraOption(args, &i, &camera)) {
      } else
        throw BadOption(a, std::string(kOniRecordUsage) + kCameraUsage);
    }
    if (camera.device.uri.empty()) throw UsageError("--device is required");
    if (out.empty()) throw UsageError("-o FILE.oni is required");
  } catch (const UsageError& e) {
    std::fprintf(stderr, "graspfill oni-record: %s\n%s", e.what(), kOniRecordUsage);
    return 2;
  }
  io::CheckOutputFile(out, force);  // throws naming the file
  DepthFrame frame;
  int64_t frames = 0, bad = 0;
  std::string mode;
  {
    rt::OpenNI2Source source(camera.device);  // throws naming the device
    source.StartRecording(out);
    mode = source.mode_text();
    const auto start = std::chrono::steady_clock::now();
    for (;;) {
      if (max_frames > 0 && frames >= max_frames) break;
      if (duration_s > 0 &&
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > duration_s) {
        break;
      }
      const rt::FrameResult r = source.Next(&frame);
      if (r == rt::FrameResult::kEndOfStream) break;
      if (r == rt::FrameResult::kOk)
        ++frames;
      else
        ++bad;
    }
  }  // the recorder writes what it holds and its index as the source closes
  // Read the file back: OpenNI2's recorder reports no error of its own.
  rt::OpenNI2Source::Config check;
  check.uri = out;
  rt::OpenNI2Source playback(check);
  int64_t recorded = 0;
  rt::FrameResult r;
  while ((r = playback.Next(&frame)) != rt::FrameResult::kEndOfStream) recorded += r == rt::FrameResult::kOk;
  std::printf("oni-record: %lld frames (%s) into %s, %lld read back; %lld bad\n",
              static_cast<long long>(frames), mode.c_str(), out.c_str(), static_cast<long long>(recorded),
              static_cast<long long>(bad));
  if (recorded != frames) {
    std::fprintf(stderr, "graspfill oni-record: %s holds %lld of the %lld frames read\n", out.c_str(),
                 static_cast<long long>(recorded), static_cast<long long>(frames));
    return 1;
  }
  return 0;
}

}  // namespace graspfill::cli
