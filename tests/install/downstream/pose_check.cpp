// SPDX-License-Identifier: BSD-3-Clause
// The part of graspfill small enough to build from source in the
// add_subdirectory test: a recording's depth frames posed by the
// interpolated gripper states (graspfill::rt_sources, graspfill::core), and
// the OpenNI2 source as the build configured it.
//
// usage: pose_check RECORDING.lcmlog [--expect-no-openni2]
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "graspfill/core/pose_interpolation.hpp"
#include "sources/lcm_log_source.hpp"
#include "sources/openni2_source.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: pose_check RECORDING.lcmlog [--expect-no-openni2]\n");
    return 2;
  }
  const bool expect_no_openni2 = argc > 2 && std::string(argv[2]) == "--expect-no-openni2";
  int failures = 0;
  auto check = [&failures](bool ok, const std::string& what) {
    std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
    if (!ok) ++failures;
  };

  graspfill::rt::LcmLogSource::Config config;
  config.path = argv[1];
  graspfill::rt::LcmLogSource source(config);
  graspfill::GripperStateBuffer states(1 << 16, 50000);
  std::vector<int64_t> depth_utimes;
  graspfill::rt::SourceEvent event;
  for (graspfill::rt::FrameResult r; (r = source.Next(&event)) != graspfill::rt::FrameResult::kEndOfStream;) {
    if (r != graspfill::rt::FrameResult::kOk) continue;
    if (event.kind == graspfill::rt::SourceEvent::Kind::kDepth) {
      depth_utimes.push_back(event.depth.utime);
    } else if (event.kind == graspfill::rt::SourceEvent::Kind::kGripperState) {
      states.Push(event.gripper);
    }
  }
  size_t posed = 0;
  for (const int64_t utime : depth_utimes) {
    graspfill::GripperState state;
    if (states.Lookup(utime, &state) == graspfill::PoseLookup::kOk && graspfill::IsValidPose(state.T_C_G)) {
      ++posed;
    }
  }
  std::printf("depth frames %zu, posed %zu, gripper states %zu\n", depth_utimes.size(), posed, states.size());
  // The bundled recording: 36 depth frames, all bracketed by gripper states
  // but maybe the first and the last.
  check(depth_utimes.size() >= 30, "at least 30 depth frames");
  check(posed + 2 >= depth_utimes.size(), "all depth frames posed but at most two");

  std::string openni2_error;
  try {
    graspfill::rt::OpenNI2Source::Config camera;
    camera.uri = "/nonexistent/recording.oni";
    graspfill::rt::OpenNI2Source camera_source(camera);
  } catch (const std::exception& e) {
    openni2_error = e.what();
  }
  std::printf("OpenNI2Source: %s\n", openni2_error.c_str());
  check(!openni2_error.empty(), "no OpenNI2 source opens a missing recording");
  const bool built_without = openni2_error.find("built without OpenNI2") != std::string::npos;
  check(built_without == expect_no_openni2,
        expect_no_openni2 ? "built without OpenNI2" : "built with OpenNI2");

  std::printf("%s\n", failures == 0 ? "PASSED" : "FAILED");
  return failures == 0 ? 0 : 1;
}
