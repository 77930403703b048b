// SPDX-License-Identifier: BSD-3-Clause
// OpenNI2Source without a camera: construction fails with OpenNI2's own
// reason. (CI machines have no depth camera; on a desk with one plugged in
// the any-device test skips.)
#include "sources/openni2_source.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace graspfill::rt {
namespace {

TEST(OpenNI2Source, NoDeviceThrowsWithOpenNIError) {
  OpenNI2Source::Config config;  // any device
  try {
    OpenNI2Source source(config);
    GTEST_SKIP() << "a depth camera is attached; nothing to test here";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("OpenNI2: cannot open any device"), std::string::npos) << what;
    // OpenNI2's extended error, e.g. "DeviceOpen using default: no devices
    // found".
    EXPECT_NE(what.find("no devices found"), std::string::npos) << what;
  }
}

TEST(OpenNI2Source, MissingRecordingThrowsNamingIt) {
  OpenNI2Source::Config config;
  config.uri = "/nonexistent/graspfill_test.oni";
  try {
    OpenNI2Source source(config);
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'/nonexistent/graspfill_test.oni'"), std::string::npos) << what;
    EXPECT_NE(what.find("Couldn't open device"), std::string::npos) << what;
  }
}

TEST(OpenNI2Source, CanBeRetriedAfterAFailure) {
  // A failed construction must shut OpenNI2 down again (reference counted):
  // a second attempt reports the same error instead of a stale state.
  for (int i = 0; i < 2; ++i) {
    OpenNI2Source::Config config;
    config.uri = "/nonexistent/again.oni";
    EXPECT_THROW(OpenNI2Source source(config), std::runtime_error);
  }
}

}  // namespace
}  // namespace graspfill::rt
