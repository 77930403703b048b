// SPDX-License-Identifier: BSD-3-Clause
// CameraSource with a graspfill-replay device: the log's session first,
// then its gripper states and the device's depth frames (through libOpenNI2)
// in time order, every one of them, as LcmLogSource reads the same log.
#include "sources/camera_source.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace graspfill::rt {
namespace {

const std::string kLog = std::string(GRASPFILL_SOURCE_DIR) + "/replay/default/recording.lcmlog";

struct Counts {
  int depth = 0, states = 0, sessions = 0;
  std::vector<int64_t> depth_utimes;
};

Counts Read(FrameSource* source, bool check_order) {
  Counts c;
  SourceEvent event;
  FrameResult r;
  int64_t last = INT64_MIN;
  while ((r = source->Next(&event)) != FrameResult::kEndOfStream) {
    EXPECT_EQ(r, FrameResult::kOk) << event.error;
    if (r != FrameResult::kOk) continue;
    int64_t t = 0;
    if (event.kind == SourceEvent::Kind::kDepth) {
      ++c.depth;
      c.depth_utimes.push_back(t = event.depth.utime);
    } else if (event.kind == SourceEvent::Kind::kGripperState) {
      ++c.states;
      t = event.gripper.utime;
    } else {
      ++c.sessions;
      continue;
    }
    if (check_order) {
      EXPECT_GE(t, last);
    }
    last = t;
  }
  return c;
}

TEST(CameraSource, ReplayDeviceMergesTheLogsStatesWithItsFrames) {
  LcmLogSource::Config log_config;
  log_config.path = kLog;
  log_config.session_events = true;
  LcmLogSource log(log_config);
  const Counts want = Read(&log, false);
  ASSERT_GT(want.depth, 10);

  CameraSource::Config config;
  config.device.uri = "graspfill-replay:" + kLog;
  config.device.replay_speed = 0.0f;
  CameraSource source(config);
  EXPECT_EQ(source.session().has_value(), want.sessions > 0);
  SourceEvent first;
  if (want.sessions > 0) {
    ASSERT_EQ(source.Next(&first), FrameResult::kOk);
    EXPECT_EQ(first.kind, SourceEvent::Kind::kSession);
  }
  const Counts got = Read(&source, true);
  EXPECT_EQ(got.depth, want.depth);
  EXPECT_EQ(got.states, want.states);
  EXPECT_EQ(got.depth_utimes, want.depth_utimes);  // the recorded stamps
}

TEST(CameraSource, UnknownModeListsTheDevicesModes) {
  CameraSource::Config config;
  config.device.uri = "graspfill-replay:" + kLog;
  config.device.width = 1000;
  try {
    CameraSource source(config);
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("has no depth mode 1000x*@*/1mm; available: "), std::string::npos) << what;
    EXPECT_NE(what.find("/100um"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace graspfill::rt
