// The repair stage's contract: clouds come out repaired on the stage's own
// thread, a newer cloud replaces one still waiting, Submit never waits for
// the stage, a failed repair still publishes, and destruction never hangs.
//
// No timing thresholds: where a test needs the stage busy it holds the
// stage's thread inside the output callback (a CallbackGate), which stands
// in for a slow repair since both keep the thread from the mailbox.
#include "module/repair_stage.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

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
  RepairStage stage(repair::RepairConfig{}, [&](const ObjectCloud& c) { out.Record(c); });
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
  RepairStage stage(repair::RepairConfig{}, [&](const ObjectCloud& c) {
    out.Record(c);
    gate.PassOrWait();
  });
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
  EXPECT_EQ(busy.repaired, 1);
  EXPECT_EQ(busy.published, 0);  // cloud 0's callback has not returned
  gate.Open();
  stage.Drain();
  EXPECT_EQ(stage.status().published, 2);
}

TEST(RepairStage, AFailedRepairIsCountedAndPublishedUnrepaired) {
  Published out;
  RepairStage stage(repair::RepairConfig{}, [&](const ObjectCloud& c) { out.Record(c); });
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
  EXPECT_EQ(published.timings.size(), bad.timings.size());

  // The stage carries on with the next cloud.
  stage.Submit(ProtocolCloudWithSeq(2));
  stage.Drain();
  s = stage.status();
  EXPECT_EQ(s.repaired, 1);
  EXPECT_EQ(s.failed, 1);
  ASSERT_EQ(out.clouds.size(), 2u);
  EXPECT_GT(out.clouds[1].size(), ProtocolCloud().size());
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
