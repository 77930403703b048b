// SPDX-License-Identifier: BSD-3-Clause
// libGraspfillReplay through Debian's libOpenNI2 (loaded from the build's
// runtime folder by this test's RPATH): a recording served as a device
// gives the log's depth frames, in order, with their recorded timestamps
// and values, in the modes it lists; a bad log is a clear error.
#include <OpenNI.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "drivers/openni2_replay/graspfill_replay_properties.hpp"
#include "sources/lcm_log_source.hpp"

namespace graspfill::rt {
namespace {

const std::string kLog = std::string(GRASPFILL_SOURCE_DIR) + "/replay/default/recording.lcmlog";

std::vector<DepthFrame> LogDepthFrames(const std::string& path) {
  LcmLogSource::Config config;
  config.path = path;
  LcmLogSource source(config);
  std::vector<DepthFrame> frames;
  SourceEvent event;
  FrameResult r;
  while ((r = source.Next(&event)) != FrameResult::kEndOfStream) {
    if (r == FrameResult::kOk && event.kind == SourceEvent::Kind::kDepth) frames.push_back(event.depth);
  }
  return frames;
}

class ReplayDriver : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(openni::OpenNI::initialize(), openni::STATUS_OK) << openni::OpenNI::getExtendedError();
  }
  void TearDown() override { openni::OpenNI::shutdown(); }
};

TEST_F(ReplayDriver, ServesEveryDepthFrameOfTheLogWithItsTimestamp) {
  const std::vector<DepthFrame> expected = LogDepthFrames(kLog);
  ASSERT_GT(expected.size(), 10u);
  openni::Device device;
  ASSERT_EQ(device.open((std::string(openni2_replay::kUriPrefix) + kLog).c_str()), openni::STATUS_OK)
      << openni::OpenNI::getExtendedError();
  const float speed = 0.0f;  // as fast as read
  ASSERT_EQ(device.setProperty(openni2_replay::kDevicePropertySpeed, speed), openni::STATUS_OK);
  openni::VideoStream stream;
  ASSERT_EQ(stream.create(device, openni::SENSOR_DEPTH), openni::STATUS_OK);
  const CameraIntrinsics& K = expected.front().intrinsics;
  // Modes: the recorded size in mm (its own units) first, then 100 um, then half size.
  const auto& modes = stream.getSensorInfo().getSupportedVideoModes();
  ASSERT_EQ(modes.getSize(), 4);
  EXPECT_EQ(modes[0].getResolutionX(), K.width);
  EXPECT_EQ(modes[0].getPixelFormat(), openni::PIXEL_FORMAT_DEPTH_1_MM);
  EXPECT_EQ(modes[2].getResolutionX(), K.width / 2);
  EXPECT_EQ(modes[0].getFps(), 30);
  EXPECT_NEAR(stream.getHorizontalFieldOfView(), 2 * std::atan(0.5 * K.width / K.fx), 1e-6);
  double intrinsics[4];
  int size = sizeof(intrinsics);
  ASSERT_EQ(stream.getProperty(openni2_replay::kStreamPropertyIntrinsics, intrinsics, &size),
            openni::STATUS_OK);
  EXPECT_EQ(intrinsics[0], K.fx);
  EXPECT_EQ(intrinsics[3], K.cy);
  ASSERT_EQ(stream.start(), openni::STATUS_OK);
  openni::VideoFrameRef frame;
  for (size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(stream.readFrame(&frame), openni::STATUS_OK) << "frame " << i;
    EXPECT_EQ(static_cast<int64_t>(frame.getTimestamp()), expected[i].utime) << "frame " << i;
    ASSERT_EQ(frame.getWidth(), K.width);
    const auto* units = static_cast<const uint16_t*>(frame.getData());
    int differing = 0;
    for (size_t p = 0; p < expected[i].depth_m.size(); ++p) {
      const auto want = static_cast<uint16_t>(std::lround(expected[i].depth_m[p] * 1000.0));
      differing += units[p] != want;
    }
    EXPECT_EQ(differing, 0) << "frame " << i;
  }
  int left = -1;
  ASSERT_EQ(device.getProperty(openni2_replay::kDevicePropertyFramesLeft, &left), openni::STATUS_OK);
  EXPECT_EQ(left, 0);
  // Nothing more: a wait times out instead of repeating a frame.
  openni::VideoStream* streams[] = {&stream};
  int ready = -1;
  EXPECT_EQ(openni::OpenNI::waitForAnyStream(streams, 1, &ready, 100), openni::STATUS_TIME_OUT);
  stream.stop();
  stream.destroy();
  device.close();
}

TEST_F(ReplayDriver, HalfSizeModeTakesEverySecondPixel) {
  const std::vector<DepthFrame> expected = LogDepthFrames(kLog);
  openni::Device device;
  ASSERT_EQ(device.open((std::string(openni2_replay::kUriPrefix) + kLog).c_str()), openni::STATUS_OK);
  ASSERT_EQ(device.setProperty(openni2_replay::kDevicePropertySpeed, 0.0f), openni::STATUS_OK);
  openni::VideoStream stream;
  ASSERT_EQ(stream.create(device, openni::SENSOR_DEPTH), openni::STATUS_OK);
  const CameraIntrinsics& K = expected.front().intrinsics;
  openni::VideoMode mode;
  mode.setResolution(K.width / 2, K.height / 2);
  mode.setFps(30);
  mode.setPixelFormat(openni::PIXEL_FORMAT_DEPTH_100_UM);
  ASSERT_EQ(stream.setVideoMode(mode), openni::STATUS_OK);
  ASSERT_EQ(stream.start(), openni::STATUS_OK);
  openni::VideoFrameRef frame;
  ASSERT_EQ(stream.readFrame(&frame), openni::STATUS_OK);
  ASSERT_EQ(frame.getWidth(), K.width / 2);
  const auto* units = static_cast<const uint16_t*>(frame.getData());
  const int u = K.width / 4, v = K.height / 4;  // the image centre
  const float want_m = expected[0].at(2 * u, 2 * v);
  EXPECT_EQ(units[v * (K.width / 2) + u], static_cast<uint16_t>(std::lround(want_m * 10000.0)));
  double intrinsics[4];
  int size = sizeof(intrinsics);
  ASSERT_EQ(stream.getProperty(openni2_replay::kStreamPropertyIntrinsics, intrinsics, &size),
            openni::STATUS_OK);
  EXPECT_EQ(intrinsics[0], K.fx / 2);
  EXPECT_EQ(intrinsics[2], K.cx / 2);
}

TEST_F(ReplayDriver, MissingLogIsAnErrorNamingIt) {
  openni::Device device;
  EXPECT_NE(device.open("graspfill-replay:/nonexistent/x.lcmlog"), openni::STATUS_OK);
  const std::string error = openni::OpenNI::getExtendedError();
  EXPECT_NE(error.find("cannot open log '/nonexistent/x.lcmlog': no such file"), std::string::npos) << error;
}

}  // namespace
}  // namespace graspfill::rt
