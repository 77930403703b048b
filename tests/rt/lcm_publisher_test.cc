// SPDX-License-Identifier: BSD-3-Clause
// LcmPublisher over LCM's in-process memq:// provider: what is published
// arrives, decoded, with its content intact. (No network: memq only.)
#include "sinks/lcm_publisher.hpp"

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <stdexcept>
#include <string>
#include <vector>

#include "graspfill/io/messages.hpp"
#include "test_cloud.hpp"

namespace graspfill::rt {
namespace {

// Collects raw messages on one channel. Subscribed through
// subscribeFunction, as LcmBusSubscriber subscribes: under GCC 12 with
// -fsanitize=address,undefined at -O1, lcm-cpp's member-function form
// (LCM::subscribe(channel, &C::method, obj), LCMMHUntypedSubscription::cb_func)
// calls the handler through a register that does not hold the subscription
// (UBSan: "possibly invalid vptr", then a member call on 0xbebebe...01),
// so the ASan step (scripts/test_sanitizers.sh) could not run these tests.
class Collector {
 public:
  static void Receive(const lcm::ReceiveBuffer* buffer, const std::string& channel, Collector* self) {
    self->OnMessage(buffer, channel);
  }
  void OnMessage(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
    const auto* data = static_cast<const uint8_t*>(buffer->data);
    messages.emplace_back(data, data + buffer->data_size);
    channels.push_back(channel);
  }
  std::vector<std::vector<uint8_t>> messages;
  std::vector<std::string> channels;
};

// Handles until `count` messages arrived, bounded at ~2 s.
void Pump(lcm::LCM* lcm, const Collector& collector, size_t count) {
  for (int i = 0; i < 20 && collector.messages.size() < count; ++i) {
    ASSERT_GE(lcm->handleTimeout(100), 0);
  }
}

TEST(LcmPublisher, CloudArrivesOverMemq) {
  LcmPublisher dut("memq://");
  Collector collector;
  dut.lcm_instance()->subscribeFunction("LcmPublisher.CloudArrivesOverMemq", &Collector::Receive, &collector);
  const ObjectCloud cloud = testing::MakeTestCloud(5000, 21);
  ASSERT_TRUE(dut.PublishCloud("LcmPublisher.CloudArrivesOverMemq", cloud));
  Pump(dut.lcm_instance(), collector, 1);
  ASSERT_EQ(collector.messages.size(), 1u);

  ObjectCloud received;
  std::string error;
  ASSERT_TRUE(
      io::DecodeObjectCloud(collector.messages[0].data(), collector.messages[0].size(), &received, &error))
      << error;
  EXPECT_EQ(received.size(), 5000u);
  EXPECT_EQ(received.seq, cloud.seq);
  EXPECT_EQ(received.utime, cloud.utime);
  // The published bytes are the cloud's encoding, whole: the same as
  // encoding and decoding it here (the packing itself: messages_test).
  const ObjectCloud expected = testing::AsOnTheWire(cloud);
  EXPECT_EQ(received.points_G, expected.points_G);
  EXPECT_EQ(received.normals_G, expected.normals_G);
  EXPECT_EQ(received.provenance, cloud.provenance);
  ASSERT_EQ(received.holes.size(), 1u);
  EXPECT_EQ(received.holes[0].kind, HoleKind::kMissingSurface);
  EXPECT_EQ(received.holes[0].points_added, 500);
  EXPECT_EQ(testing::CloudChecksum(received), testing::CloudChecksum(expected));
}

TEST(LcmPublisher, StatusAndRawOverMemq) {
  LcmPublisher dut("memq://");
  Collector collector;
  dut.lcm_instance()->subscribeFunction("LcmPublisher.Status.*", &Collector::Receive, &collector);
  io::ModuleStatus status;
  status.frames_in = 30;
  status.frames_dropped = 2;
  status.state = "running";
  ASSERT_TRUE(dut.PublishStatus("LcmPublisher.Status.A", status));
  ASSERT_TRUE(dut.PublishRaw("LcmPublisher.Status.B", {7, 8, 9}));
  Pump(dut.lcm_instance(), collector, 2);
  ASSERT_EQ(collector.messages.size(), 2u);
  EXPECT_EQ(collector.channels[0], "LcmPublisher.Status.A");
  io::ModuleStatus received;
  std::string error;
  ASSERT_TRUE(
      io::DecodeModuleStatus(collector.messages[0].data(), collector.messages[0].size(), &received, &error))
      << error;
  EXPECT_EQ(received.frames_in, 30);
  EXPECT_EQ(received.frames_dropped, 2);
  EXPECT_EQ(received.state, "running");
  EXPECT_EQ(collector.messages[1], (std::vector<uint8_t>{7, 8, 9}));
}

TEST(LcmPublisher, CollisionMeshArrivesOverMemqAndAnInconsistentOneIsNot) {
  LcmPublisher dut("memq://");
  Collector collector;
  dut.lcm_instance()->subscribeFunction("LcmPublisher.Mesh", &Collector::Receive, &collector);
  io::CollisionMeshMessage mesh;
  mesh.seq = 3;
  mesh.grasp_id = 2;
  mesh.mesh.vertices = {{0, 0, 0}, {0.05f, 0, 0}, {0, 0.05f, 0}, {0, 0, 0.05f}};
  mesh.mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  mesh.watertight = true;
  mesh.deviation_m = 0.0005;
  ASSERT_TRUE(dut.PublishCollisionMesh("LcmPublisher.Mesh", mesh));
  io::CollisionMeshMessage broken = mesh;
  broken.mesh.triangles.push_back({0, 1, 4});  // no vertex 4
  EXPECT_FALSE(dut.PublishCollisionMesh("LcmPublisher.Mesh", broken));
  Pump(dut.lcm_instance(), collector, 2);
  ASSERT_EQ(collector.messages.size(), 1u);
  io::CollisionMeshMessage received;
  std::string error;
  ASSERT_TRUE(
      io::DecodeCollisionMesh(collector.messages[0].data(), collector.messages[0].size(), &received, &error))
      << error;
  EXPECT_EQ(received.seq, 3);
  EXPECT_EQ(received.grasp_id, 2);
  EXPECT_EQ(received.mesh.triangles, mesh.mesh.triangles);
  EXPECT_EQ(received.mesh.vertices, mesh.mesh.vertices);
  EXPECT_TRUE(received.watertight);
}

TEST(LcmPublisher, InconsistentCloudIsNotPublished) {
  LcmPublisher dut("memq://");
  ObjectCloud cloud = testing::MakeTestCloud(10, 1);
  cloud.normals_G.pop_back();
  EXPECT_FALSE(dut.PublishCloud("LcmPublisher.Inconsistent", cloud));
}

TEST(LcmPublisher, BadUrlThrowsNamingIt) {
  try {
    LcmPublisher dut("nosuchprovider://x");
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nosuchprovider://x"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace graspfill::rt
