// SPDX-License-Identifier: BSD-3-Clause
// The warning a publisher gives when a model will not fit a default
// subscriber's receive buffer (rt/sinks/receive_buffer.hpp).
#include "sinks/receive_buffer.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

namespace graspfill::rt {
namespace {

// Debian 12's defaults.
const ReceiveBufferSettings kDebian{212992, 212992};

TEST(ReceiveBuffer, OnlyUdpMulticastMessagesPastTheShareAreWarnedAbout) {
  ::unsetenv("LCM_DEFAULT_URL");
  EXPECT_EQ(ReceiveBufferWarning(140'000, "", kDebian), "");  // the bundled model's size fits
  EXPECT_EQ(ReceiveBufferWarning(149'000, "udpm://239.255.76.67:7667?ttl=0", kDebian), "");
  const std::string warning = ReceiveBufferWarning(300'000, "", kDebian);
  EXPECT_NE(warning.find("300 kB"), std::string::npos) << warning;
  EXPECT_NE(warning.find("net.core.rmem_default = 212992"), std::string::npos) << warning;
  EXPECT_NE(warning.find("?recv_buf_size=428572"), std::string::npos) << warning;  // 300000 / 0.7
  // The kernel's cap is below what a subscriber should ask for: say so.
  EXPECT_NE(warning.find("sysctl -w net.core.rmem_max=428572"), std::string::npos) << warning;
  const std::string roomy = ReceiveBufferWarning(300'000, "", {212992, 8 << 20});
  EXPECT_NE(roomy.find("recv_buf_size"), std::string::npos);
  EXPECT_EQ(roomy.find("rmem_max"), std::string::npos) << roomy;
  // Other providers have no such buffer; unknown settings give no guess.
  EXPECT_EQ(ReceiveBufferWarning(10'000'000, "memq://", kDebian), "");
  EXPECT_EQ(ReceiveBufferWarning(10'000'000, "file:///tmp/x.lcmlog?mode=w", kDebian), "");
  EXPECT_EQ(ReceiveBufferWarning(10'000'000, "", {}), "");
}

TEST(ReceiveBuffer, TheDefaultUrlIsLcmDefaultUrlWhenSet) {
  ::setenv("LCM_DEFAULT_URL", "memq://", 1);
  EXPECT_FALSE(IsUdpMulticast(""));
  ::setenv("LCM_DEFAULT_URL", "udpm://239.255.76.67:7667?ttl=1", 1);
  EXPECT_TRUE(IsUdpMulticast(""));
  ::unsetenv("LCM_DEFAULT_URL");
  EXPECT_TRUE(IsUdpMulticast(""));
  EXPECT_FALSE(IsUdpMulticast("tcpq://localhost:7700"));
}

TEST(ReceiveBuffer, TheKernelsSettingsAreReadFromProc) {
  const ReceiveBufferSettings s = ReadReceiveBufferSettings();
  if (!s.rmem_default) GTEST_SKIP() << "no /proc/sys/net/core here";
  EXPECT_GT(*s.rmem_default, 0u);
  ASSERT_TRUE(s.rmem_max.has_value());
}

}  // namespace
}  // namespace graspfill::rt
