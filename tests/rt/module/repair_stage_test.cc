// SPDX-License-Identifier: BSD-3-Clause
// The repair stage's contract: clouds come out repaired on the stage's own
// thread, a newer cloud replaces one still waiting, Submit never waits for
// the stage, a failed repair still publishes, and destruction never hangs.
//
// No timing thresholds: where a test needs the stage busy it holds the
// stage's thread inside the output callback (a CallbackGate), which stands
// in for a slow repair since both keep the thread from the mailbox.
#include "module/repair_stage.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "module/cloud_repair.hpp"
#include "protocol_cloud.hpp"

namespace graspfill::rt {
namespace {

// Holds the stage's thread in the callback until the test opens it.
class CallbackGate {
 public:
  void PassOrWait() {
    std::unique_lock<std::mutex> lock(mutex_);
    ++entered_;
    changed_.notify_all();
    changed_.wait(lock, [&] { return open_; });
  }
  void WaitUntilEntered(int times) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return entered_ >= times; });
  }
  void Open() {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = true;
    changed_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  int entered_{0};
  bool open_{false};
};

// What the callback received, in order, and on which thread.
struct Published {
  std::mutex mutex;
  std::vector<ObjectCloud> clouds;
  std::thread::id thread;

  void Record(const ObjectCloud& cloud) {
    std::lock_guard<std::mutex> lock(mutex);
    clouds.push_back(cloud);
    thread = std::this_thread::get_id();
  }
};

// One protocol cloud for the whole suite, re-stamped per submission.
const ObjectCloud& ProtocolCloud() {
  static const ObjectCloud cloud = testing::MakeProtocolObjectCloud(0);
  return cloud;
}

ObjectCloud ProtocolCloudWithSeq(int64_t seq) {
  ObjectCloud cloud = ProtocolCloud();
  cloud.seq = seq;
  return cloud;
}

TEST(RepairStage, PublishesTheRepairedCloudFromItsOwnThread) {
  Published out;
  RepairStageOptions full;  // every cloud repaired on the stage's thread
  full.incremental = false;
  RepairStage stage(
      repair::RepairConfig{}, [&](const ObjectCloud& c) { out.Record(c); }, full);
  const ObjectCloud fused = ProtocolCloudWithSeq(1);
  stage.Submit(fused);
  stage.Drain();

  ASSERT_EQ(out.clouds.size(), 1u);
  EXPECT_NE(out.thread, std::this_thread::get_id());
  const ObjectCloud& cloud = out.clouds[0];
  EXPECT_EQ(cloud.seq, 1);
  ASSERT_TRUE(testing::FusedThenAdded(fused, cloud));
  EXPECT_FALSE(cloud.holes.empty());

  const RepairStageStatus s = stage.status();
  EXPECT_EQ(s.submitted, 1);
  EXPECT_EQ(s.repaired, 1);
  EXPECT_EQ(s.superseded, 0);
  EXPECT_EQ(s.failed, 0);
  EXPECT_EQ(s.published, 1);
  EXPECT_EQ(s.last_status, "repaired");
  EXPECT_EQ(s.last_points_in, fused.size());
  EXPECT_EQ(s.last_points_out, cloud.size());
  EXPECT_GT(s.last_repair_ms, 0.0);
}

TEST(RepairStage, ANewerCloudSupersedesTheOneWaiting) {
  CallbackGate gate;
  Published out;
  RepairStageOptions full;  // every cloud repaired on the stage's thread
  full.incremental = false;
  RepairStage stage(
      repair::RepairConfig{},
      [&](const ObjectCloud& c) {
        out.Record(c);
        gate.PassOrWait();
      },
      full);
  stage.Submit(ProtocolCloudWithSeq(0));
  gate.WaitUntilEntered(1);  // the stage is busy with cloud 0 from here on
  for (int64_t seq = 1; seq <= 4; ++seq) stage.Submit(ProtocolCloudWithSeq(seq));
  {
    const RepairStageStatus s = stage.status();
    EXPECT_EQ(s.submitted, 5);
    EXPECT_EQ(s.superseded, 3);  // 1, 2 and 3, each replaced by the next
  }
  gate.Open();
  stage.Drain();

  const RepairStageStatus s = stage.status();
  EXPECT_EQ(s.submitted, 5);
  EXPECT_EQ(s.repaired, 2);
  EXPECT_LT(s.repaired, s.submitted);
  EXPECT_EQ(s.superseded, 3);
  EXPECT_EQ(s.failed, 0);
  EXPECT_EQ(s.repaired + s.superseded + s.failed, s.submitted);
  ASSERT_EQ(out.clouds.size(), 2u);
  EXPECT_EQ(out.clouds[0].seq, 0);
  EXPECT_EQ(out.clouds[1].seq, 4);  // the freshest, repaired too
  EXPECT_GT(out.clouds[1].size(), ProtocolCloud().size());
}

// The stage's thread is held by the test for the whole of the Submits, so
// a Submit that waited for the stage would never return (ctest's timeout
// would end the test) instead of reaching the checks below.
TEST(RepairStage, SubmitNeverWaitsForTheStage) {
  CallbackGate gate;
  Published out;
  RepairStage stage(repair::RepairConfig{}, [&](const ObjectCloud& c) {
    out.Record(c);
    gate.PassOrWait();
  });
  stage.Submit(ProtocolCloudWithSeq(0));
  gate.WaitUntilEntered(1);
  stage.Submit(ProtocolCloudWithSeq(1));
  stage.Submit(ProtocolCloudWithSeq(2));
  const RepairStageStatus busy = stage.status();  // status() does not wait either
  EXPECT_EQ(busy.submitted, 3);
  EXPECT_EQ(busy.repaired + busy.unrepaired, 1);  // cloud 0: out before its full repair
  EXPECT_EQ(busy.published, 0);                   // cloud 0's callback has not returned
  gate.Open();
  stage.Drain();
  EXPECT_EQ(stage.status().published, 2);
}

TEST(RepairStage, AFailedRepairIsCountedAndPublishedUnrepaired) {
  Published out;
  RepairStageOptions full;  // the failure of a repair on the stage's own thread
  full.incremental = false;
  RepairStage stage(
      repair::RepairConfig{}, [&](const ObjectCloud& c) { out.Record(c); }, full);
  ObjectCloud bad = ProtocolCloudWithSeq(1);
  bad.points_G[17].y() = std::nanf("");  // Repair throws std::invalid_argument
  stage.Submit(bad);
  stage.Drain();

  RepairStageStatus s = stage.status();
  EXPECT_EQ(s.failed, 1);
  EXPECT_EQ(s.repaired, 0);
  EXPECT_EQ(s.published, 1);
  EXPECT_NE(s.last_status.find("failed"), std::string::npos) << s.last_status;
  ASSERT_EQ(out.clouds.size(), 1u);
  const ObjectCloud& published = out.clouds[0];
  EXPECT_EQ(published.seq, 1);
  EXPECT_EQ(published.size(), bad.size());
  EXPECT_EQ(published.provenance, bad.provenance);
  EXPECT_TRUE(published.holes.empty());
  // The input's timings, then the stage's latency parts only.
  ASSERT_GE(published.timings.size(), bad.timings.size());
  for (size_t i = bad.timings.size(); i < published.timings.size(); ++i) {
    EXPECT_EQ(published.timings[i].stage.rfind("latency_", 0), 0u) << published.timings[i].stage;
  }

  // The stage carries on with the next cloud.
  stage.Submit(ProtocolCloudWithSeq(2));
  stage.Drain();
  s = stage.status();
  EXPECT_EQ(s.repaired, 1);
  EXPECT_EQ(s.failed, 1);
  ASSERT_EQ(out.clouds.size(), 2u);
  EXPECT_GT(out.clouds[1].size(), ProtocolCloud().size());
}

double TimingMs(const ObjectCloud& cloud, const std::string& stage) {
  for (const StageTiming& t : cloud.timings) {
    if (t.stage == stage) return t.ms;
  }
  return -1.0;
}

// Waits (bounded) until the stage's background repair has landed `n` times.
void WaitForRebases(const RepairStage& stage, int64_t n) {
  for (int i = 0; i < 1200 && stage.status().rebases < n; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

// Incremental: a grasp's first cloud goes out as fused while its full
// repair runs behind; the next one of the same grasp is an update of that
// repair, which keeps its fills (nothing new was measured).
TEST(RepairStage, UpdatesTheLastFullRepairBetweenFullRepairs) {
  Published out;
  RepairStage stage(repair::RepairConfig{}, [&](const ObjectCloud& c) { out.Record(c); });
  stage.Submit(ProtocolCloudWithSeq(1));
  stage.Drain();
  WaitForRebases(stage, 1);
  stage.Submit(ProtocolCloudWithSeq(2));
  stage.Drain();
  const RepairStageStatus s = stage.status();
  EXPECT_EQ(s.unrepaired, 1);
  EXPECT_EQ(s.rebases, 1);
  EXPECT_EQ(s.last_rebase_reason, "no base");
  EXPECT_EQ(s.updates, 1);
  EXPECT_EQ(s.full_published, 0);
  EXPECT_EQ(s.repaired, 1);
  ASSERT_EQ(out.clouds.size(), 2u);
  EXPECT_EQ(out.clouds[0].points_G, ProtocolCloud().points_G);  // out before any repair
  // The update is the background repair of the same cloud, point for point.
  ObjectCloud full = ProtocolCloudWithSeq(2);
  RepairObjectCloud(repair::RepairConfig{}, &full);
  const ObjectCloud& update = out.clouds[1];
  ASSERT_GT(full.size(), ProtocolCloud().size());
  EXPECT_EQ(update.points_G, full.points_G);
  EXPECT_EQ(update.provenance, full.provenance);
  EXPECT_GE(TimingMs(update, "repair_update"), 0.0);
  EXPECT_EQ(s.update_ms.count, 1u);
  EXPECT_EQ(s.full_ms.count, 1u);
  EXPECT_LT(s.update_ms.max, s.full_ms.max);
}

TEST(RepairStage, WithoutIncrementalEveryCloudIsRepairedInFull) {
  Published out;
  RepairStageOptions options;
  options.incremental = false;
  RepairStage stage(
      repair::RepairConfig{}, [&](const ObjectCloud& c) { out.Record(c); }, options);
  stage.Submit(ProtocolCloudWithSeq(1));
  stage.Drain();
  stage.Submit(ProtocolCloudWithSeq(2));
  stage.Drain();
  const RepairStageStatus s = stage.status();
  EXPECT_EQ(s.full_published, 2);
  EXPECT_EQ(s.updates, 0);
  EXPECT_EQ(s.full_ms.count, 2u);
}

// A cloud with much new surface is published as an update at once, and
// repaired in full behind it: that repair becomes the next base.
TEST(RepairStage, ALargeChangeRebasesInTheBackground) {
  Published out;
  RepairStage stage(repair::RepairConfig{}, [&](const ObjectCloud& c) { out.Record(c); });
  stage.Submit(ProtocolCloudWithSeq(1));
  stage.Drain();
  WaitForRebases(stage, 1);
  ObjectCloud grown = ProtocolCloudWithSeq(2);
  const size_t n = grown.size();
  for (size_t i = 0; i < n / 5; ++i) {  // 20% more surface, 20 cm away
    grown.points_G.push_back(grown.points_G[i] + Eigen::Vector3f(0.2f, 0.0f, 0.0f));
    if (!grown.normals_G.empty()) grown.normals_G.push_back(grown.normals_G[i]);
    grown.provenance.push_back(Provenance::kObserved);
  }
  stage.Submit(grown);
  stage.Drain();
  WaitForRebases(stage, 2);
  const RepairStageStatus s = stage.status();
  EXPECT_EQ(s.updates, 1);
  EXPECT_EQ(s.rebases, 2);
  EXPECT_EQ(s.last_rebase_reason, "new surface");
  EXPECT_EQ(s.full_ms.count, 2u);  // the first cloud's and the grown one's
}

// The stage measures the age from the newest frame's arrival the module
// stamped on the cloud, and keeps the stamp on the repaired cloud.
TEST(RepairStage, AddsItsPartToTheCloudsLatency) {
  Published out;
  RepairStage stage(repair::RepairConfig{}, [&](const ObjectCloud& c) { out.Record(c); });
  ObjectCloud cloud = ProtocolCloudWithSeq(1);
  cloud.newest_frame_arrival = std::chrono::steady_clock::now() - std::chrono::milliseconds(25);
  stage.Submit(cloud);
  stage.Drain();
  ASSERT_EQ(out.clouds.size(), 1u);
  const double repair_ms = TimingMs(out.clouds[0], "latency_repair");
  const double wait_ms = TimingMs(out.clouds[0], "latency_repair_wait");
  ASSERT_GT(repair_ms, 0.0);
  ASSERT_GE(wait_ms, 0.0);
  EXPECT_GE(TimingMs(out.clouds[0], "latency_frame_to_repaired"), 25.0 + repair_ms + wait_ms - 1e-6);
  EXPECT_EQ(out.clouds[0].newest_frame_arrival, cloud.newest_frame_arrival);
}

TEST(RepairStage, ACloudWithNoArrivalGetsNoFrameAge) {
  Published out;
  RepairStage stage(repair::RepairConfig{}, [&](const ObjectCloud& c) { out.Record(c); });
  stage.Submit(ProtocolCloudWithSeq(1));
  stage.Drain();
  ASSERT_EQ(out.clouds.size(), 1u);
  for (const StageTiming& t : out.clouds[0].timings) {
    EXPECT_NE(t.stage, "latency_frame_to_repaired");
  }
  EXPECT_EQ(out.clouds[0].newest_frame_arrival, std::chrono::steady_clock::time_point{});
}

TEST(RepairStage, DestructionWithACloudWaitingDoesNotHang) {
  CallbackGate gate;
  Published out;
  auto stage = std::make_unique<RepairStage>(repair::RepairConfig{}, [&](const ObjectCloud& c) {
    out.Record(c);
    gate.PassOrWait();
  });
  stage->Submit(ProtocolCloudWithSeq(0));
  gate.WaitUntilEntered(1);
  stage->Submit(ProtocolCloudWithSeq(1));  // certainly waiting in the mailbox
  gate.Open();
  stage.reset();  // whether cloud 1 was taken or not, this returns
  std::lock_guard<std::mutex> lock(out.mutex);
  EXPECT_GE(out.clouds.size(), 1u);
  EXPECT_LE(out.clouds.size(), 2u);

  // And straight after a Submit, the repair just started or not yet.
  auto quick = std::make_unique<RepairStage>(repair::RepairConfig{}, nullptr);
  quick->Submit(ProtocolCloudWithSeq(2));
  quick->Submit(ProtocolCloudWithSeq(3));
  quick.reset();
}

TEST(RepairStage, RejectsABadConfig) {
  repair::RepairConfig config;
  config.up_hint = Eigen::Vector3d::Zero();
  EXPECT_THROW(RepairStage(config, nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::rt
