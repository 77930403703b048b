// SPDX-License-Identifier: BSD-3-Clause
// The claws of session descriptions are built and compared off the caller's
// thread (issue 36: a late 10,000-link URDF held the status for 9 s): Submit
// never waits for a build, each verdict is remembered by the claw's
// identity, another claw is told once, an unloadable one every time.
#include "module/session_claw_checker.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace graspfill::rt {
namespace {

using Clock = std::chrono::steady_clock;

io::SessionDescription Named(const std::string& name, const std::string& text = "{}") {
  io::SessionDescription s;
  s.claw_name = name;
  s.claw_text = text;
  return s;
}

// Claws by name: "slow" takes 1.5 s to build, "bad" cannot be built.
struct Rig {
  std::atomic<int> builds{0};
  std::mutex mutex;
  std::vector<std::string> unloadable, other;
  SessionClawChecker checker{
      [this](const io::SessionDescription& s) {
        ++builds;
        if (s.claw_name == "bad") throw std::runtime_error("mesh 'x.stl' not found");
        if (s.claw_name == "slow") std::this_thread::sleep_for(std::chrono::milliseconds(1500));
        return s.claw_name == "three-finger" ? claw::ClawModel::ThreeFinger() : claw::ClawModel::Parallel();
      },
      [](const claw::ClawModel& a, const claw::ClawModel& b) { return a.name() == b.name(); },
      SessionClawChecker::Callbacks{[this](const io::SessionDescription& s, const std::string& why) {
                                      std::lock_guard<std::mutex> lock(mutex);
                                      unloadable.push_back(s.claw_name + ": " + why);
                                    },
                                    [this](const io::SessionDescription& s) {
                                      std::lock_guard<std::mutex> lock(mutex);
                                      other.push_back(s.claw_name);
                                    }}};
};

TEST(SessionClawChecker, SubmitNeverWaitsForABuild) {
  Rig rig;
  rig.checker.SetClawInUse(claw::ClawModel::ThreeFinger(), Named("three-finger"));
  const auto start = Clock::now();
  rig.checker.Submit(Named("slow"));
  for (int i = 0; i < 10; ++i) rig.checker.Submit(Named("slow"));  // being built: not again
  const double submit_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  EXPECT_LT(submit_ms, 200.0);
  EXPECT_FALSE(rig.checker.Idle());
  ASSERT_TRUE(rig.checker.WaitIdle(std::chrono::seconds(10)));
  EXPECT_EQ(rig.builds, 1);
  EXPECT_EQ(rig.other, std::vector<std::string>{"slow"});
}

TEST(SessionClawChecker, AnotherClawIsToldOnceAnUnloadableOneEveryTime) {
  Rig rig;
  rig.checker.SetClawInUse(claw::ClawModel::ThreeFinger(), Named("three-finger"));
  for (int round = 0; round < 3; ++round) {
    rig.checker.Submit(Named("three-finger"));  // the claw in use: nothing to do
    rig.checker.Submit(Named("parallel"));
    rig.checker.Submit(Named("bad"));
    ASSERT_TRUE(rig.checker.WaitIdle(std::chrono::seconds(10)));
  }
  EXPECT_EQ(rig.builds, 2);  // parallel and bad, once each
  EXPECT_EQ(rig.other, std::vector<std::string>{"parallel"});
  ASSERT_EQ(rig.unloadable.size(), 3u);
  EXPECT_EQ(rig.unloadable[2], "bad: mesh 'x.stl' not found");
  // The same name with other text is another claw: judged on its own.
  rig.checker.Submit(Named("parallel", R"({"other": 1})"));
  ASSERT_TRUE(rig.checker.WaitIdle(std::chrono::seconds(10)));
  EXPECT_EQ(rig.builds, 3);
  EXPECT_EQ(rig.other.size(), 2u);
}

TEST(SessionClawChecker, BeforeTheClawInUseTheFirstBuiltIsKept) {
  Rig rig;
  rig.checker.Submit(Named("bad"));
  rig.checker.Submit(Named("parallel"));
  rig.checker.Submit(Named("three-finger"));
  ASSERT_TRUE(rig.checker.WaitIdle(std::chrono::seconds(10)));
  const std::optional<DescribedClaw> first = rig.checker.FirstBuilt();
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->session.claw_name, "parallel");
  EXPECT_EQ(first->claw.name(), "parallel");
  EXPECT_TRUE(rig.other.empty());  // nothing to compare with yet
  EXPECT_EQ(rig.unloadable.size(), 1u);
  // The session starts with the first (no warning about it); the one
  // built after it is compared now.
  rig.checker.SetClawInUse(first->claw, first->session);
  ASSERT_TRUE(rig.checker.WaitIdle(std::chrono::seconds(10)));
  EXPECT_EQ(rig.other, std::vector<std::string>{"three-finger"});
  EXPECT_EQ(rig.builds, 3);  // not rebuilt for the comparison
}

TEST(SessionClawChecker, AFloodKeepsTheNewestWaiting) {
  Rig rig;
  rig.checker.SetClawInUse(claw::ClawModel::ThreeFinger(), Named("three-finger"));
  rig.checker.Submit(Named("slow"));
  while (rig.builds == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));  // under way
  for (int i = 0; i < 20; ++i) rig.checker.Submit(Named("p" + std::to_string(i)));
  EXPECT_EQ(rig.checker.dropped(), 20 - static_cast<int64_t>(SessionClawChecker::kMaxWaiting));
  ASSERT_TRUE(rig.checker.WaitIdle(std::chrono::seconds(10)));
  EXPECT_EQ(rig.builds, 1 + static_cast<int>(SessionClawChecker::kMaxWaiting));
  EXPECT_EQ(rig.other.back(), "p19");
}

}  // namespace
}  // namespace graspfill::rt
