// SPDX-License-Identifier: BSD-3-Clause
// Message conversion: round trips, rejection of malformed input, and the
// size of ZLIB16 depth on a noisy plane.
#include "graspfill/io/messages.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>

#include <graspfill/depth_image_t.hpp>
#include <graspfill/gripper_state_t.hpp>
#include <graspfill/module_status_t.hpp>
#include <graspfill/object_cloud_t.hpp>
#include <graspfill/session_description_t.hpp>

namespace graspfill::io {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
// Poses go through a quaternion and back: equal up to rounding.
constexpr double kPoseTolerance = 1e-12;

template <typename Message>
std::vector<uint8_t> Encode(const Message& msg) {
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  EXPECT_EQ(msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  return bytes;
}

// Overwrites a big-endian int32 at `offset` (to forge bad counts).
void PokeInt32(std::vector<uint8_t>* bytes, size_t offset, uint32_t value) {
  for (int i = 0; i < 4; ++i) (*bytes)[offset + i] = value >> (24 - 8 * i);
}

DepthFrame SmallFrame() {
  DepthFrame frame;
  frame.utime = 1700000000123456;
  frame.intrinsics = {5, 3, 4.5, 4.25, 2.0, 1.0};
  frame.depth_m = {0.0f,   0.5f,  0.5004f, 0.4996f, 1.2345f,  //
                   kNaN,   -1.0f, 65.535f, 70.0f,   0.0004f,  //
                   0.001f, 2.0f,  1.999f,  0.75f,   std::numeric_limits<float>::infinity()};
  return frame;
}

// What decoding must give back for depth d at `scale` meters per unit.
float Quantized(float d, double scale) {
  if (!std::isfinite(d) || d <= 0.0f) return 0.0f;
  const double units = std::round(d / scale);
  if (units > 65535.0) return 0.0f;
  return static_cast<float>(units * scale);
}

void ExpectQuantizedEqual(const DepthFrame& in, const DepthFrame& out, double scale) {
  EXPECT_EQ(out.utime, in.utime);
  EXPECT_EQ(out.intrinsics, in.intrinsics);
  ASSERT_EQ(out.depth_m.size(), in.depth_m.size());
  for (size_t i = 0; i < in.depth_m.size(); ++i) {
    EXPECT_EQ(out.depth_m[i], Quantized(in.depth_m[i], scale)) << "pixel " << i;
  }
}

TEST(DepthImageMessage, Raw16RoundTripIsExactOnQuantizedDepth) {
  const DepthFrame frame = SmallFrame();
  const auto bytes = EncodeDepthImage(frame, DepthEncoding::kRaw16, 0.001);
  DepthFrame out;
  std::string error;
  ASSERT_TRUE(DecodeDepthImage(bytes.data(), bytes.size(), &out, &error)) << error;
  ExpectQuantizedEqual(frame, out, 0.001);
  // Spot checks of the quantization rules themselves.
  EXPECT_EQ(out.depth_m[2], 0.5f);     // 0.5004 -> 500 mm
  EXPECT_EQ(out.depth_m[7], 65.535f);  // the last representable
  EXPECT_EQ(out.depth_m[8], 0.0f);     // beyond range -> invalid
  EXPECT_EQ(out.depth_m[5], 0.0f);     // NaN -> invalid
  EXPECT_EQ(out.depth_m[6], 0.0f);     // negative -> invalid
  EXPECT_EQ(out.depth_m[9], 0.0f);     // rounds to 0 units -> invalid
}

TEST(DepthImageMessage, Zlib16RoundTripEqualsRaw16) {
  const DepthFrame frame = SmallFrame();
  for (double scale : {0.001, 0.0001}) {
    const auto raw = EncodeDepthImage(frame, DepthEncoding::kRaw16, scale);
    const auto zlib = EncodeDepthImage(frame, DepthEncoding::kZlib16, scale);
    DepthFrame from_raw, from_zlib;
    std::string error;
    ASSERT_TRUE(DecodeDepthImage(raw.data(), raw.size(), &from_raw, &error));
    ASSERT_TRUE(DecodeDepthImage(zlib.data(), zlib.size(), &from_zlib, &error)) << error;
    ExpectQuantizedEqual(frame, from_zlib, scale);
    EXPECT_EQ(from_zlib.depth_m, from_raw.depth_m);
  }
}

TEST(DepthImageMessage, WireFormatIsTheGeneratedType) {
  const DepthFrame frame = SmallFrame();
  const auto bytes = EncodeDepthImage(frame, DepthEncoding::kRaw16, 0.001);
  graspfill::depth_image_t msg{};
  ASSERT_EQ(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  EXPECT_EQ(msg.width, 5);
  EXPECT_EQ(msg.height, 3);
  EXPECT_EQ(msg.fx, 4.5);
  EXPECT_EQ(msg.depth_scale, 0.001);
  EXPECT_EQ(msg.encoding, int8_t{graspfill::depth_image_t::RAW16});
  ASSERT_EQ(msg.num_bytes, 30);
  // Pixel 1 is 500 mm, little-endian.
  EXPECT_EQ(msg.data[2], 500 & 0xff);
  EXPECT_EQ(msg.data[3], 500 >> 8);
}

// A 640x480 plane 0.8..1.1 m away, tilted, with Kinect-like noise.
DepthFrame NoisyPlane(double sigma_m, double dropout, uint32_t seed) {
  DepthFrame frame;
  frame.utime = 42;
  const int w = frame.intrinsics.width, h = frame.intrinsics.height;
  frame.depth_m.resize(static_cast<size_t>(w) * h);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma_m);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const double z = 0.8 + 0.0004 * u + 0.0002 * v + noise(rng);
      frame.depth_m[v * w + u] = uniform(rng) < dropout ? 0.0f : static_cast<float>(z);
    }
  }
  return frame;
}

TEST(DepthImageMessage, Zlib16KeepsNoisyPlaneSmall) {
  struct Case {
    double sigma_m, dropout;
    double max_ratio;  // of RAW16; measured ~0.30, 0.38, 0.36
  };
  for (const Case& c : {Case{0.0015, 0.0, 0.33}, Case{0.0015, 0.05, 0.41}, Case{0.003, 0.0, 0.39}}) {
    const DepthFrame frame = NoisyPlane(c.sigma_m, c.dropout, 7);
    const auto raw = EncodeDepthImage(frame, DepthEncoding::kRaw16);
    const auto t0 = std::chrono::steady_clock::now();
    const auto zlib = EncodeDepthImage(frame, DepthEncoding::kZlib16);
    const auto t1 = std::chrono::steady_clock::now();
    DepthFrame out;
    std::string error;
    ASSERT_TRUE(DecodeDepthImage(zlib.data(), zlib.size(), &out, &error));
    const auto t2 = std::chrono::steady_clock::now();
    ExpectQuantizedEqual(frame, out, 0.001);
    const double ratio = static_cast<double>(zlib.size()) / raw.size();
    std::printf(
        "noisy plane sigma %.1f mm dropout %.0f%%: RAW16 %zu B, ZLIB16 %zu "
        "B/frame (%.2f), encode %.1f ms, decode %.1f ms\n",
        c.sigma_m * 1e3, c.dropout * 100, raw.size(), zlib.size(), ratio,
        std::chrono::duration<double, std::milli>(t1 - t0).count(),
        std::chrono::duration<double, std::milli>(t2 - t1).count());
    EXPECT_LT(ratio, c.max_ratio);
  }
}

TEST(DepthImageMessage, DecodeReusesTheOutputBuffer) {
  const DepthFrame frame = NoisyPlane(0.0015, 0.0, 3);
  const auto bytes = EncodeDepthImage(frame);
  DepthFrame out;
  std::string error;
  ASSERT_TRUE(DecodeDepthImage(bytes.data(), bytes.size(), &out, &error));
  const float* buffer = out.depth_m.data();
  ASSERT_TRUE(DecodeDepthImage(bytes.data(), bytes.size(), &out, &error));
  EXPECT_EQ(out.depth_m.data(), buffer);
}

TEST(DepthImageMessage, RejectsWrongSizes) {
  graspfill::depth_image_t msg{};
  msg.width = 4;
  msg.height = 2;
  msg.fx = msg.fy = 500.0;
  msg.cx = 1.5;
  msg.cy = 0.5;
  msg.depth_scale = 0.001;
  msg.encoding = graspfill::depth_image_t::RAW16;
  msg.num_bytes = 15;  // one byte short of 4*2*2
  msg.data.assign(15, 0);
  DepthFrame out;
  std::string error;
  auto bytes = Encode(msg);
  EXPECT_FALSE(DecodeDepthImage(bytes.data(), bytes.size(), &out, &error));
  EXPECT_NE(error.find("RAW16 data has 15 bytes, expected 16"), std::string::npos) << error;

  msg.num_bytes = 16;
  msg.data.assign(16, 0);
  for (auto [w, h] : {std::pair{0, 8}, std::pair{-4, -2}, std::pair{1 << 16, 1 << 16}}) {
    msg.width = w;
    msg.height = h;
    bytes = Encode(msg);
    EXPECT_FALSE(DecodeDepthImage(bytes.data(), bytes.size(), &out, &error));
    EXPECT_NE(error.find("bad image size"), std::string::npos) << error;
  }

  // A frame whose depth does not match its intrinsics is caller misuse.
  DepthFrame frame = SmallFrame();
  frame.depth_m.pop_back();
  EXPECT_THROW(EncodeDepthImage(frame), std::invalid_argument);
  EXPECT_THROW(EncodeDepthImage(SmallFrame(), DepthEncoding::kRaw16, 0.0), std::invalid_argument);
}

TEST(DepthImageMessage, RejectsBadIntrinsicsScaleAndEncoding) {
  const auto good = EncodeDepthImage(SmallFrame(), DepthEncoding::kZlib16);
  graspfill::depth_image_t msg{};
  ASSERT_GT(msg.decode(good.data(), 0, static_cast<int>(good.size())), 0);
  DepthFrame out;
  std::string error;

  auto expect_rejected = [&](graspfill::depth_image_t bad, const std::string& reason) {
    const auto bytes = Encode(bad);
    error.clear();
    EXPECT_FALSE(DecodeDepthImage(bytes.data(), bytes.size(), &out, &error));
    EXPECT_NE(error.find(reason), std::string::npos) << error;
  };
  auto bad = msg;
  bad.fx = std::nan("");
  expect_rejected(bad, "bad intrinsics");
  bad = msg;
  bad.cy = kInf;
  expect_rejected(bad, "bad intrinsics");
  bad = msg;
  bad.fy = -1.0;
  expect_rejected(bad, "bad intrinsics");
  bad = msg;
  bad.depth_scale = 0.0;
  expect_rejected(bad, "bad depth_scale");
  bad = msg;
  bad.encoding = 7;
  expect_rejected(bad, "unknown encoding 7");
  bad = msg;
  bad.data[bad.data.size() / 2] ^= 0x5a;  // corrupt the deflate stream
  bad.data.back() ^= 0xff;                // and its checksum
  expect_rejected(bad, "zlib");
  bad = msg;
  bad.width = 4;  // stream inflates to more bytes than 4x3 needs
  expect_rejected(bad, "zlib");
}

TEST(DepthImageMessage, RejectsMalformedBytes) {
  const auto bytes = EncodeDepthImage(SmallFrame(), DepthEncoding::kZlib16);
  DepthFrame out;
  std::string error;
  // Every truncation.
  for (size_t n = 0; n < bytes.size(); ++n) {
    EXPECT_FALSE(DecodeDepthImage(bytes.data(), n, &out, &error)) << n;
    EXPECT_FALSE(error.empty());
  }
  // A trailing byte.
  auto longer = bytes;
  longer.push_back(0);
  EXPECT_FALSE(DecodeDepthImage(longer.data(), longer.size(), &out, &error));
  EXPECT_NE(error.find("trailing"), std::string::npos) << error;
  // Another message type.
  const auto gripper = EncodeGripperState(GripperState{});
  EXPECT_FALSE(DecodeDepthImage(gripper.data(), gripper.size(), &out, &error));
  EXPECT_NE(error.find("type hash"), std::string::npos) << error;
  // A num_bytes that claims more than is there (offset: hash, utime, w, h,
  // 5 doubles, encoding).
  auto forged = bytes;
  PokeInt32(&forged, 8 + 8 + 4 + 4 + 5 * 8 + 1, 0x7fffffff);
  EXPECT_FALSE(DecodeDepthImage(forged.data(), forged.size(), &out, &error));
  PokeInt32(&forged, 8 + 8 + 4 + 4 + 5 * 8 + 1, 0xffffffff);
  EXPECT_FALSE(DecodeDepthImage(forged.data(), forged.size(), &out, &error));
  // Null output, null error pointer.
  EXPECT_FALSE(DecodeDepthImage(bytes.data(), bytes.size(), nullptr, &error));
  EXPECT_FALSE(DecodeDepthImage(bytes.data(), 3, &out, nullptr));
}

// ---- Gripper state -------------------------------------------------------------

Eigen::Isometry3d SomePose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.12, -0.05, 0.83);
  return T;
}

void ExpectPoseNear(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  EXPECT_TRUE(a.matrix().isApprox(b.matrix(), kPoseTolerance)) << a.matrix() << "\nvs\n" << b.matrix();
}

TEST(GripperStateMessage, CameraFrameRoundTrip) {
  GripperState state;
  state.utime = 1234567;
  state.T_C_G = SomePose();
  state.opening_m = 0.031;
  state.joint_values = {0.1, -0.2, 0.3};
  const auto bytes = EncodeGripperState(state);
  GripperState out;
  out.joint_values = {9, 9, 9, 9, 9};
  std::string error;
  // T_C_B must not matter for camera-frame messages.
  ASSERT_TRUE(DecodeGripperState(bytes.data(), bytes.size(), SomePose(), &out, &error)) << error;
  EXPECT_EQ(out.utime, state.utime);
  ExpectPoseNear(out.T_C_G, state.T_C_G);
  EXPECT_EQ(out.opening_m, state.opening_m);
  EXPECT_EQ(out.joint_values, state.joint_values);
}

graspfill::gripper_state_t BaseFrameMessage() {
  graspfill::gripper_state_t msg{};
  msg.utime = 99;
  msg.frame = graspfill::gripper_state_t::FRAME_BASE;
  // T_B_G: G 0.5 m along the base's x and 0.3 m up, axes aligned.
  msg.position[0] = 0.5;
  msg.position[1] = 0.0;
  msg.position[2] = 0.3;
  msg.orientation[0] = 1.0;
  msg.opening_m = 0.02;
  msg.num_joints = 0;
  return msg;
}

TEST(GripperStateMessage, BaseFrameIsConvertedWithHandEye) {
  // T_C_B: base rotated +90 deg about the camera's x axis, origin at
  // (0.1, -0.2, 1.0) in C.
  Eigen::Isometry3d T_C_B = Eigen::Isometry3d::Identity();
  T_C_B.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  T_C_B.translation() = Eigen::Vector3d(0.1, -0.2, 1.0);
  const auto bytes = Encode(BaseFrameMessage());
  GripperState out;
  std::string error;
  ASSERT_TRUE(DecodeGripperState(bytes.data(), bytes.size(), T_C_B, &out, &error)) << error;
  // By hand: R_x(90) (0.5, 0, 0.3) = (0.5, -0.3, 0); plus the origin.
  EXPECT_TRUE(out.T_C_G.translation().isApprox(Eigen::Vector3d(0.6, -0.5, 1.0), kPoseTolerance))
      << out.T_C_G.translation().transpose();
  // G's z axis (base up) points along -y in the camera (image up).
  EXPECT_TRUE(
      (out.T_C_G.linear() * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d(0, -1, 0), kPoseTolerance));
  EXPECT_EQ(out.utime, 99);
  EXPECT_EQ(out.opening_m, 0.02);
  EXPECT_TRUE(out.joint_values.empty());
}

TEST(GripperStateMessage, RejectsNonFiniteAndNonUnit) {
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  GripperState out;
  std::string error;
  auto decode = [&](const graspfill::gripper_state_t& msg) {
    const auto bytes = Encode(msg);
    error.clear();
    return DecodeGripperState(bytes.data(), bytes.size(), I, &out, &error);
  };
  auto msg = BaseFrameMessage();
  msg.position[1] = std::nan("");
  EXPECT_FALSE(decode(msg));
  EXPECT_NE(error.find("pose is not finite"), std::string::npos) << error;

  msg = BaseFrameMessage();
  msg.orientation[2] = std::nan("");
  EXPECT_FALSE(decode(msg));
  EXPECT_NE(error.find("pose is not finite"), std::string::npos) << error;

  msg = BaseFrameMessage();
  msg.opening_m = kInf;
  EXPECT_FALSE(decode(msg));
  EXPECT_NE(error.find("not finite"), std::string::npos) << error;

  msg = BaseFrameMessage();
  msg.num_joints = 2;
  msg.joint_values = {0.1, std::nan("")};
  EXPECT_FALSE(decode(msg));

  msg = BaseFrameMessage();
  msg.orientation[0] = 1.01;
  EXPECT_FALSE(decode(msg));
  EXPECT_NE(error.find("unit quaternion"), std::string::npos) << error;

  msg = BaseFrameMessage();
  msg.orientation[0] = 0.0;  // all zero
  EXPECT_FALSE(decode(msg));

  msg = BaseFrameMessage();
  msg.frame = 5;
  EXPECT_FALSE(decode(msg));
  EXPECT_NE(error.find("unknown frame 5"), std::string::npos) << error;

  // Within tolerance: accepted and renormalized.
  msg = BaseFrameMessage();
  msg.orientation[0] = 1.0005;
  ASSERT_TRUE(decode(msg)) << error;
  EXPECT_NEAR(Eigen::Quaterniond(out.T_C_G.rotation()).norm(), 1.0, 1e-12);
  EXPECT_TRUE(out.T_C_G.linear().isApprox(Eigen::Matrix3d::Identity(), 1e-12));
}

TEST(GripperStateMessage, RejectsMalformedBytes) {
  GripperState state;
  state.joint_values = {1, 2};
  const auto bytes = EncodeGripperState(state);
  GripperState out;
  std::string error;
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  for (size_t n = 0; n < bytes.size(); ++n) {
    EXPECT_FALSE(DecodeGripperState(bytes.data(), n, I, &out, &error)) << n;
  }
  // num_joints sits after hash, utime, frame, 3 + 4 doubles and opening.
  constexpr size_t kNumJointsOffset = 8 + 8 + 1 + 7 * 8 + 8;
  for (uint32_t forged : {0xffffffffu, 0x7fffffffu, 3u}) {
    auto bad = bytes;
    PokeInt32(&bad, kNumJointsOffset, forged);
    EXPECT_FALSE(DecodeGripperState(bad.data(), bad.size(), I, &out, &error));
    EXPECT_NE(error.find("malformed"), std::string::npos) << error;
  }
  const auto depth = EncodeDepthImage(SmallFrame());
  EXPECT_FALSE(DecodeGripperState(depth.data(), depth.size(), I, &out, &error));
}

// ---- Object cloud ----------------------------------------------------------------

ObjectCloud SomeCloud(bool normals) {
  ObjectCloud cloud;
  cloud.utime = 1700000000000001;
  cloud.seq = 17;
  cloud.frame_name = "gripper";
  cloud.T_C_G = SomePose();
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> coord(-0.05f, 0.05f);
  for (int i = 0; i < 100; ++i) {
    cloud.points_G.emplace_back(coord(rng), coord(rng), coord(rng));
    if (normals) cloud.normals_G.push_back(cloud.points_G.back().normalized());
    cloud.provenance.push_back(static_cast<Provenance>(i % 3));
  }
  HoleSummary claw;
  claw.kind = HoleKind::kClaw;
  claw.boundary_points = 40;
  claw.box_min_G = {-0.01f, 0.02f, 0.0f};
  claw.box_max_G = {0.01f, 0.03f, 0.05f};
  claw.points_added = 120;
  claw.confidence = 0.6f;
  HoleSummary top = claw;
  top.kind = HoleKind::kMissingSurface;
  top.points_added = 0;
  top.confidence = 0.0f;
  top.unobserved = true;  // an open mouth: nothing added, unknown inside
  cloud.holes = {claw, top};
  cloud.timings = {{"fusion", 4.5}, {"repair/poisson", 120.25}};
  return cloud;
}

void ExpectCloudEqual(const ObjectCloud& a, const ObjectCloud& b) {
  EXPECT_EQ(a.utime, b.utime);
  EXPECT_EQ(a.seq, b.seq);
  EXPECT_EQ(a.frame_name, b.frame_name);
  ExpectPoseNear(a.T_C_G, b.T_C_G);
  // The packed points (object_cloud_t.lcm): positions within half a 50 um
  // step (these clouds are 10 cm across), normals within a degree,
  // confidence within half of 1/255.
  ASSERT_EQ(a.points_G.size(), b.points_G.size());
  for (size_t i = 0; i < a.points_G.size(); ++i) {
    EXPECT_LE((a.points_G[i] - b.points_G[i]).cwiseAbs().maxCoeff(), 25.001e-6f) << i;
  }
  ASSERT_EQ(a.normals_G.size(), b.normals_G.size());
  for (size_t i = 0; i < a.normals_G.size(); ++i) {
    EXPECT_GT(a.normals_G[i].dot(b.normals_G[i]), std::cos(1.0 * M_PI / 180.0)) << i;
    EXPECT_NEAR(b.normals_G[i].norm(), 1.0f, 1e-6f) << i;
  }
  const size_t n = a.points_G.size();
  EXPECT_EQ(b.provenance,
            a.provenance.empty() ? std::vector<Provenance>(n, Provenance::kObserved) : a.provenance);
  ASSERT_EQ(b.confidence.size(), n);
  for (size_t i = 0; i < n; ++i) {
    EXPECT_NEAR(b.confidence[i], a.confidence.empty() ? 1.0f : a.confidence[i], 0.5f / 255.0f + 1e-7f) << i;
  }
  ASSERT_EQ(a.holes.size(), b.holes.size());
  for (size_t i = 0; i < a.holes.size(); ++i) {
    EXPECT_EQ(a.holes[i].kind, b.holes[i].kind);
    EXPECT_EQ(a.holes[i].boundary_points, b.holes[i].boundary_points);
    EXPECT_EQ(a.holes[i].box_min_G, b.holes[i].box_min_G);
    EXPECT_EQ(a.holes[i].box_max_G, b.holes[i].box_max_G);
    EXPECT_EQ(a.holes[i].points_added, b.holes[i].points_added);
    EXPECT_EQ(a.holes[i].unobserved, b.holes[i].unobserved);
    EXPECT_EQ(a.holes[i].confidence, b.holes[i].confidence);
  }
  ASSERT_EQ(a.timings.size(), b.timings.size());
  for (size_t i = 0; i < a.timings.size(); ++i) {
    EXPECT_EQ(a.timings[i].stage, b.timings[i].stage);
    EXPECT_EQ(a.timings[i].ms, b.timings[i].ms);
  }
}

TEST(ObjectCloudMessage, RoundTripWithHolesAndTimings) {
  for (bool normals : {true, false}) {
    const ObjectCloud cloud = SomeCloud(normals);
    const auto bytes = EncodeObjectCloud(cloud);
    ObjectCloud out = SomeCloud(true);  // stale content must be replaced
    out.timings.push_back({"stale", 1});
    std::string error;
    ASSERT_TRUE(DecodeObjectCloud(bytes.data(), bytes.size(), &out, &error)) << error;
    ExpectCloudEqual(cloud, out);
  }
}

TEST(ObjectCloudMessage, EmptyCloudAndDefaultProvenance) {
  ObjectCloud empty;
  auto bytes = EncodeObjectCloud(empty);
  ObjectCloud out = SomeCloud(true);
  std::string error;
  ASSERT_TRUE(DecodeObjectCloud(bytes.data(), bytes.size(), &out, &error));
  ExpectCloudEqual(empty, out);

  ObjectCloud no_provenance = SomeCloud(false);
  no_provenance.provenance.clear();
  bytes = EncodeObjectCloud(no_provenance);
  ASSERT_TRUE(DecodeObjectCloud(bytes.data(), bytes.size(), &out, &error));
  EXPECT_EQ(out.provenance, std::vector<Provenance>(100, Provenance::kObserved));
}

TEST(ObjectCloudMessage, EncodeRejectsInconsistentCloud) {
  ObjectCloud cloud = SomeCloud(true);
  cloud.normals_G.pop_back();
  EXPECT_THROW(EncodeObjectCloud(cloud), std::invalid_argument);
  cloud = SomeCloud(true);
  cloud.provenance.pop_back();
  EXPECT_THROW(EncodeObjectCloud(cloud), std::invalid_argument);
}

TEST(ObjectCloudMessage, RejectsBadContent) {
  const auto good = EncodeObjectCloud(SomeCloud(true));
  graspfill::object_cloud_t msg{};
  ASSERT_GT(msg.decode(good.data(), 0, static_cast<int>(good.size())), 0);
  ObjectCloud out;
  std::string error;
  auto expect_rejected = [&](const graspfill::object_cloud_t& bad, const std::string& reason) {
    const auto bytes = Encode(bad);
    error.clear();
    EXPECT_FALSE(DecodeObjectCloud(bytes.data(), bytes.size(), &out, &error));
    EXPECT_NE(error.find(reason), std::string::npos) << error;
  };
  auto bad = msg;
  bad.holes[1].kind = 7;
  expect_rejected(bad, "unknown hole kind 7");
  bad = msg;
  bad.holes[0].confidence = std::nanf("");
  expect_rejected(bad, "its confidence in 0..1");
  bad = msg;
  bad.holes[0].confidence = 1.5f;
  expect_rejected(bad, "its confidence in 0..1");
  bad = msg;
  bad.holes[1].unobserved = 2;
  expect_rejected(bad, "unobserved must be 0 or 1");
  // A safe bound whose bytes do not hold its voxels, one bit per voxel
  // rounded up to a byte: 3 x 2 x 3 voxels take exactly 3 bytes. Counts
  // whose product overflows 64 bits are refused too.
  bad = msg;
  bad.bound_voxel_m = 0.005f;
  bad.bound_nx = 3, bad.bound_ny = 2, bad.bound_nz = 3;
  for (const int bytes : {2, 4}) {
    bad.bound_num_bytes = bytes;
    bad.bound_bits.assign(static_cast<size_t>(bytes), 0xff);
    expect_rejected(bad, "inconsistent safe bound");
  }
  bad.bound_num_bytes = 3;
  bad.bound_bits = {0xff, 0xff, 0x03};  // every voxel set, no bit past them
  {
    const auto bytes = Encode(bad);
    EXPECT_TRUE(DecodeObjectCloud(bytes.data(), bytes.size(), &out, &error)) << error;
    EXPECT_EQ(out.safe_bound.count(), 18u);
  }
  bad.bound_nx = bad.bound_ny = bad.bound_nz = std::numeric_limits<int32_t>::max();
  expect_rejected(bad, "inconsistent safe bound");
  bad = msg;
  bad.position[2] = std::nan("");
  expect_rejected(bad, "pose is not finite");
  bad = msg;
  bad.orientation[1] += 0.1;
  expect_rejected(bad, "unit quaternion");
  // The packed points: a count the stream does not hold, a cut stream, a
  // step below 50 um, a non-finite origin, has_normals not 0 or 1.
  bad = msg;
  bad.num_points += 1;
  expect_rejected(bad, "the points inflate to");
  bad = msg;
  bad.has_normals = 0;
  expect_rejected(bad, "the points inflate to");
  bad = msg;
  bad.num_packed_bytes -= 4;
  bad.packed_points.resize(static_cast<size_t>(bad.num_packed_bytes));
  expect_rejected(bad, "not a whole zlib stream");
  bad = msg;
  bad.step_m = 1e-6;
  expect_rejected(bad, "step below");
  bad = msg;
  bad.origin[1] = std::nan("");
  expect_rejected(bad, "non-finite origin");
  bad = msg;
  bad.step_m = 1e300;  // points beyond float's range
  expect_rejected(bad, "non-finite point coordinate");
  bad = msg;
  bad.has_normals = 2;
  expect_rejected(bad, "has_normals 2");
  // A count no deflated stream of this size can hold is refused before
  // anything is allocated for it.
  bad = msg;
  bad.num_points = 2'000'000'000;
  expect_rejected(bad, "cannot be in");
  // Provenance outside 0..2 inside the packed arrays.
  ObjectCloud odd = SomeCloud(true);
  odd.provenance[3] = static_cast<Provenance>(5);
  const auto odd_bytes = EncodeObjectCloud(odd);
  EXPECT_FALSE(DecodeObjectCloud(odd_bytes.data(), odd_bytes.size(), &out, &error));
  EXPECT_NE(error.find("unknown provenance 5"), std::string::npos) << error;
}

// Non-finite points and normals cannot be packed: refused when encoded.
TEST(ObjectCloudMessage, EncodeRefusesNonFiniteValues) {
  ObjectCloud cloud = SomeCloud(true);
  cloud.points_G[10].y() = std::nanf("");
  EXPECT_THROW(EncodeObjectCloud(cloud), std::invalid_argument);
  cloud = SomeCloud(true);
  cloud.normals_G[4].x() = std::numeric_limits<float>::infinity();
  EXPECT_THROW(EncodeObjectCloud(cloud), std::invalid_argument);
}

// A cloud wider than 65535 steps of 50 um takes a coarser step, so that
// every point still fits an int16: the error stays within half a step.
// Packing the decoded cloud again gives the same points.
TEST(ObjectCloudMessage, AWideCloudTakesACoarserStep) {
  ObjectCloud cloud;
  cloud.points_G = {{-1.9f, 0, 0}, {1.9f, 0.5f, -0.25f}, {0.123456f, -0.654321f, 0.5f}};
  const auto bytes = EncodeObjectCloud(cloud);
  graspfill::object_cloud_t msg{};
  ASSERT_GT(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  EXPECT_EQ(msg.step_m, 5e-5 * 2);  // 1.9 m over 32766 steps: twice the least step
  ObjectCloud out;
  std::string error;
  ASSERT_TRUE(DecodeObjectCloud(bytes.data(), bytes.size(), &out, &error)) << error;
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_LE((out.points_G[i] - cloud.points_G[i]).cwiseAbs().maxCoeff(), 0.5 * msg.step_m + 1e-6) << i;
  }
  ObjectCloud wide_again;
  const auto wide_bytes = EncodeObjectCloud(out);
  ASSERT_TRUE(DecodeObjectCloud(wide_bytes.data(), wide_bytes.size(), &wide_again, &error)) << error;
  EXPECT_EQ(wide_again.points_G, out.points_G);
  const ObjectCloud small = SomeCloud(true);
  ObjectCloud small_out;
  const auto small_bytes = EncodeObjectCloud(small);
  ASSERT_TRUE(DecodeObjectCloud(small_bytes.data(), small_bytes.size(), &small_out, &error)) << error;
  ObjectCloud again;
  const auto again_bytes = EncodeObjectCloud(small_out);
  ASSERT_TRUE(DecodeObjectCloud(again_bytes.data(), again_bytes.size(), &again, &error)) << error;
  EXPECT_EQ(again.points_G, small_out.points_G);
}

// The reason for the packing: a model of the bundled recording's size (26k
// points with normals) must fit LCM's default receive buffer (Debian's
// net.core.rmem_default, 212,992 bytes; 200 kB messages already lose some
// there). As floats it took 746 kB.
TEST(ObjectCloudMessage, ATypicalModelFitsTheDefaultReceiveBuffer) {
  ObjectCloud cloud;
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 0.0005f);
  // A can 66 mm across, 100 mm tall: its side at a 1.4 mm spacing.
  for (int k = 0; k < 72; ++k) {
    for (int j = 0; j < 360; ++j) {
      const float a = static_cast<float>(j) * 2.0f * static_cast<float>(M_PI) / 360.0f;
      const Eigen::Vector3f radial(std::cos(a), std::sin(a), 0.0f);
      cloud.points_G.push_back(0.033f * radial + Eigen::Vector3f(noise(rng), noise(rng), 0.0014f * k));
      cloud.normals_G.push_back(radial);
    }
  }
  cloud.provenance.assign(cloud.points_G.size(), Provenance::kObserved);
  const auto bytes = EncodeObjectCloud(cloud);
  const size_t as_floats = cloud.points_G.size() * (12 + 12 + 1 + 4);
  std::printf("%zu points: %zu bytes packed, %zu as floats\n", cloud.points_G.size(), bytes.size(),
              as_floats);
  EXPECT_LT(bytes.size(), 150'000u);
  EXPECT_LT(bytes.size() * 4, as_floats);
}

TEST(ObjectCloudMessage, RejectsMalformedBytes) {
  const auto bytes = EncodeObjectCloud(SomeCloud(true));
  ObjectCloud out;
  std::string error;
  for (size_t n = 0; n < bytes.size(); ++n) {
    ASSERT_FALSE(DecodeObjectCloud(bytes.data(), n, &out, &error)) << n;
    EXPECT_NE(error.find("malformed"), std::string::npos) << error;
  }
  // num_points sits after hash, utime, seq, frame_name ("gripper": 4 + 8
  // bytes) and 7 doubles.
  constexpr size_t kNumPointsOffset = 8 + 8 + 8 + 4 + 8 + 7 * 8;
  for (uint32_t forged : {0xffffffffu, 0x7fffffffu, 99u}) {
    auto bad = bytes;
    PokeInt32(&bad, kNumPointsOffset, forged);
    EXPECT_FALSE(DecodeObjectCloud(bad.data(), bad.size(), &out, &error));
    bad = bytes;
    PokeInt32(&bad, kNumPointsOffset + 4 + 4 * 8 + 1, forged);  // num_packed_bytes
    EXPECT_FALSE(DecodeObjectCloud(bad.data(), bad.size(), &out, &error));
  }
  // Random corruption must never crash: either a clean decode or a reason.
  std::mt19937 rng(5);
  std::uniform_int_distribution<size_t> where(0, bytes.size() - 1);
  std::uniform_int_distribution<int> what(0, 255);
  int accepted = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    auto bad = bytes;
    for (int k = 0; k < 1 + trial % 4; ++k) {
      bad[where(rng)] = static_cast<uint8_t>(what(rng));
    }
    error.clear();
    if (DecodeObjectCloud(bad.data(), bad.size(), &out, &error)) {
      ++accepted;  // e.g. a changed coordinate: still a valid cloud
    } else {
      EXPECT_FALSE(error.empty());
    }
  }
  std::printf("random corruption: %d of 3000 still decode\n", accepted);
}

TEST(ModuleStatusMessage, RoundTrip) {
  ModuleStatus status;
  status.utime = 5;
  status.frames_in = 100;
  status.frames_used = 90;
  status.frames_skipped = 7;
  status.frames_dropped = 3;
  status.frames_skipped_refine = 4;
  status.last_frame_ms = 12.5;
  status.state = "running";
  status.latency_ms_p50 = 41.5;
  status.latency_ms_p95 = 60.25;
  status.latency_ms_p99 = 88.0;
  status.latency_ms_max = 120.5;
  status.clouds_published = 33;
  status.repair_updates = 30;
  status.repairs_full = 4;
  status.update_ms_p50 = 3.5;
  status.update_ms_p99 = 9.75;
  status.full_repair_ms_p50 = 110.0;
  status.full_repair_ms_p99 = 180.5;
  status.rss_mb = 101.25;
  status.bad_messages.by_reason[static_cast<size_t>(MessageError::kMalformed)] = 18;
  status.bad_messages.by_reason[static_cast<size_t>(MessageError::kNonMonotonicTime)] = 2;
  status.decode_errors = status.bad_messages.total();
  status.frames_skipped_by_reason.Count(FrameSkipReason::kPoseGap, 5);
  status.frames_skipped_by_reason.Count(FrameSkipReason::kClockJump, 2);
  const auto bytes = EncodeModuleStatus(status);
  ModuleStatus out;
  std::string error;
  ASSERT_TRUE(DecodeModuleStatus(bytes.data(), bytes.size(), &out, &error));
  EXPECT_EQ(out.latency_ms_p50, 41.5);
  EXPECT_EQ(out.latency_ms_p95, 60.25);
  EXPECT_EQ(out.latency_ms_p99, 88.0);
  EXPECT_EQ(out.latency_ms_max, 120.5);
  EXPECT_EQ(out.clouds_published, 33);
  EXPECT_EQ(out.repair_updates, 30);
  EXPECT_EQ(out.repairs_full, 4);
  EXPECT_EQ(out.update_ms_p50, 3.5);
  EXPECT_EQ(out.update_ms_p99, 9.75);
  EXPECT_EQ(out.full_repair_ms_p50, 110.0);
  EXPECT_EQ(out.full_repair_ms_p99, 180.5);
  EXPECT_EQ(out.rss_mb, 101.25);
  EXPECT_EQ(out.frames_in, 100);
  EXPECT_EQ(out.frames_used, 90);
  EXPECT_EQ(out.frames_skipped, 7);
  EXPECT_EQ(out.frames_dropped, 3);
  EXPECT_EQ(out.frames_skipped_refine, 4);
  EXPECT_EQ(out.last_frame_ms, 12.5);
  EXPECT_EQ(out.state, "running");
  EXPECT_EQ(out.decode_errors, 20);
  EXPECT_EQ(out.bad_messages[MessageError::kMalformed], 18);
  EXPECT_EQ(out.bad_messages[MessageError::kNonMonotonicTime], 2);
  EXPECT_EQ(out.bad_messages.total(), 20);
  EXPECT_EQ(out.frames_skipped_by_reason, status.frames_skipped_by_reason);
  EXPECT_EQ(out.frames_skipped_by_reason[FrameSkipReason::kPoseGap], 5);
  EXPECT_FALSE(DecodeModuleStatus(bytes.data(), bytes.size() - 1, &out, &error));
}

// The skipped frames by reason are named on the wire too, every reason
// once; an unknown or repeated name or a negative count is a bad message.
TEST(ModuleStatusMessage, SkipReasonsByName) {
  ModuleStatus status;
  status.frames_skipped_by_reason.Count(FrameSkipReason::kClawNotSeen, 4);
  graspfill::module_status_t msg;
  const auto bytes = EncodeModuleStatus(status);
  ASSERT_EQ(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  ASSERT_EQ(msg.num_skip_reasons, static_cast<int32_t>(kNumFrameSkipReasons) - 1);
  const auto it = std::find(msg.skip_reasons.begin(), msg.skip_reasons.end(), "claw_not_seen");
  ASSERT_NE(it, msg.skip_reasons.end());
  EXPECT_EQ(msg.frames_skipped_by_reason[static_cast<size_t>(it - msg.skip_reasons.begin())], 4);
  auto decodes = [](const graspfill::module_status_t& m) {
    std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
    m.encode(b.data(), 0, static_cast<int>(b.size()));
    ModuleStatus out;
    std::string error;
    return DecodeModuleStatus(b.data(), b.size(), &out, &error);
  };
  EXPECT_TRUE(decodes(msg));
  graspfill::module_status_t unknown = msg;
  unknown.skip_reasons[0] = "gremlins";
  EXPECT_FALSE(decodes(unknown));
  graspfill::module_status_t repeated = msg;
  repeated.skip_reasons[1] = repeated.skip_reasons[0];
  EXPECT_FALSE(decodes(repeated));
  graspfill::module_status_t negative = msg;
  negative.frames_skipped_by_reason[0] = -1;
  EXPECT_FALSE(decodes(negative));
}

// The per-reason counts are named on the wire: planners read them without
// our enum, and a name we do not know, a repeated one or a negative count
// is a bad message, not a silently wrong count.
TEST(ModuleStatusMessage, BadMessageReasonsByName) {
  ModuleStatus status;
  status.bad_messages.by_reason[static_cast<size_t>(MessageError::kBadPose)] = 3;
  graspfill::module_status_t msg;
  const auto bytes = EncodeModuleStatus(status);
  ASSERT_EQ(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  ASSERT_EQ(msg.num_bad_message_reasons, static_cast<int32_t>(MessageError::kCount) - 1);
  const auto it = std::find(msg.bad_message_reasons.begin(), msg.bad_message_reasons.end(), "bad_pose");
  ASSERT_NE(it, msg.bad_message_reasons.end());
  EXPECT_EQ(msg.bad_messages[static_cast<size_t>(it - msg.bad_message_reasons.begin())], 3);

  auto decodes = [](const graspfill::module_status_t& m, MessageError* reason) {
    std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
    m.encode(b.data(), 0, static_cast<int>(b.size()));
    ModuleStatus out;
    std::string error;
    return DecodeModuleStatus(b.data(), b.size(), &out, &error, reason);
  };
  MessageError reason = MessageError::kNone;
  EXPECT_TRUE(decodes(msg, &reason));
  graspfill::module_status_t unknown = msg;
  unknown.bad_message_reasons[0] = "cosmic_ray";
  EXPECT_FALSE(decodes(unknown, &reason));
  EXPECT_EQ(reason, MessageError::kBadValue);
  graspfill::module_status_t repeated = msg;
  repeated.bad_message_reasons[1] = repeated.bad_message_reasons[0];
  EXPECT_FALSE(decodes(repeated, &reason));
  graspfill::module_status_t negative = msg;
  negative.bad_messages[0] = -1;
  EXPECT_FALSE(decodes(negative, &reason));
}

TEST(MessageChannelNames, Defaults) {
  const ChannelNames names;
  EXPECT_EQ(names.depth, "GRASPFILL_DEPTH");
  EXPECT_EQ(names.gripper_state, "GRASPFILL_GRIPPER_STATE");
  EXPECT_EQ(names.object_cloud, "GRASPFILL_OBJECT_CLOUD");
  EXPECT_EQ(names.status, "GRASPFILL_STATUS");
}

}  // namespace
}  // namespace graspfill::io

namespace graspfill::io {
namespace {

TEST(ObjectCloudMessage, CarriesConfidenceAndTheSafeBound) {
  ObjectCloud cloud;
  cloud.points_G = {{0, 0, 0.1f}, {0.01f, 0, 0.1f}, {0, 0.01f, 0.1f}};
  cloud.confidence = {1.0f, 0.6f, 0.3f};
  SafeBound& bound = cloud.safe_bound;
  bound.origin_G = {-0.1f, -0.1f, 0.0f};
  bound.voxel_m = 0.005f;
  bound.nx = 3, bound.ny = 2, bound.nz = 2;  // 12 voxels: 2 bytes
  bound.bits = {0x81, 0x0a};
  const auto bytes = EncodeObjectCloud(cloud);
  ObjectCloud out;
  std::string error;
  ASSERT_TRUE(DecodeObjectCloud(bytes.data(), bytes.size(), &out, &error)) << error;
  ASSERT_EQ(out.confidence.size(), 3u);
  for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(out.confidence[i], cloud.confidence[i], 0.5f / 255.0f) << i;
  EXPECT_EQ(out.confidence[0], 1.0f);  // observed points stay exactly 1
  EXPECT_EQ(out.safe_bound.bits, bound.bits);
  EXPECT_EQ(out.safe_bound.nx, 3);
  EXPECT_EQ(out.safe_bound.count(), 4u);
  EXPECT_TRUE(out.safe_bound.Occupied(0, 0, 0));   // bit 0
  EXPECT_TRUE(out.safe_bound.Occupied(1, 0, 1));   // bit 7: 1 + 3 * (0 + 2 * 1)
  EXPECT_FALSE(out.safe_bound.Occupied(1, 0, 0));  // bit 1
  EXPECT_TRUE(out.safe_bound.Contains({-0.1f + 0.006f, -0.1f + 0.001f, 0.007f}));
  EXPECT_FALSE(out.safe_bound.Contains({1, 1, 1}));

  // A grid the bits do not cover is refused at both ends.
  cloud.safe_bound.nz = 3;
  EXPECT_THROW(EncodeObjectCloud(cloud), std::invalid_argument);
  // Confidence outside [0, 1] (NaN too) cannot be packed.
  cloud.safe_bound.nz = 2;
  for (const float c : {1.5f, -0.1f, std::nanf("")}) {
    cloud.confidence[1] = c;
    EXPECT_THROW(EncodeObjectCloud(cloud), std::invalid_argument) << c;
  }
}

// A planner keeps the points above 0.5 (docs/planner-bindings.md): the
// byte keeps every confidence on its side of 0.5. A coin flip (0.5, a lid
// no view saw) reads back below it, and anything above it reads back
// above, each within half a step.
TEST(ObjectCloudMessage, ConfidenceKeepsItsSideOfACoinFlip) {
  ObjectCloud cloud;
  const std::vector<float> sent = {0.5f, 0.5f + 1e-4f, 0.5f - 1e-4f, 0.502f, 0.498f, 0.0f, 1.0f, 0.6f};
  for (size_t i = 0; i < sent.size(); ++i) cloud.points_G.emplace_back(0.001f * i, 0.0f, 0.1f);
  cloud.confidence = sent;
  const auto bytes = EncodeObjectCloud(cloud);
  ObjectCloud out;
  std::string error;
  ASSERT_TRUE(DecodeObjectCloud(bytes.data(), bytes.size(), &out, &error)) << error;
  ASSERT_EQ(out.confidence.size(), sent.size());
  for (size_t i = 0; i < sent.size(); ++i) {
    EXPECT_EQ(out.confidence[i] > 0.5f, sent[i] > 0.5f) << sent[i] << " read back as " << out.confidence[i];
    EXPECT_NEAR(out.confidence[i], sent[i], 0.5f / 255.0f + 1e-7f) << sent[i];
  }
  EXPECT_EQ(out.confidence[5], 0.0f);
  EXPECT_EQ(out.confidence[6], 1.0f);
}

}  // namespace
}  // namespace graspfill::io

// ---- Session description -------------------------------------------------------

namespace graspfill::io {
namespace {

SessionDescription SomeSession() {
  SessionDescription s;
  s.utime = 1700000000000123;
  s.software_version = "graspfill 9.8.7";
  s.claw_kind = SessionClawKind::kDescription;
  s.claw_name = "franka_hand";
  s.claw_text = "{\"name\": \"franka_hand\", \"links\": []}";
  s.claw_source = "config/claws/franka_hand.json";
  s.claw_mesh_root = "/opt/meshes";
  s.T_C_B = SomePose();
  s.intrinsics = CameraIntrinsics{320, 240, 290.5, 291.25, 160.5, 119.0};
  s.workspace_G = Eigen::AlignedBox3d(Eigen::Vector3d(-0.05, -0.06, 0.004), Eigen::Vector3d(0.05, 0.06, 0.2));
  s.voxel_m = 0.002;
  return s;
}

void ExpectSessionEqual(const SessionDescription& a, const SessionDescription& b) {
  EXPECT_EQ(a.utime, b.utime);
  EXPECT_EQ(a.software_version, b.software_version);
  EXPECT_EQ(a.claw_kind, b.claw_kind);
  EXPECT_EQ(a.claw_name, b.claw_name);
  EXPECT_EQ(a.claw_text, b.claw_text);
  EXPECT_EQ(a.claw_source, b.claw_source);
  EXPECT_EQ(a.claw_mesh_root, b.claw_mesh_root);
  ExpectPoseNear(a.T_C_B, b.T_C_B);
  ASSERT_EQ(a.intrinsics.has_value(), b.intrinsics.has_value());
  if (a.intrinsics) {
    EXPECT_EQ(*a.intrinsics, *b.intrinsics);
  }
  ASSERT_EQ(a.workspace_G.has_value(), b.workspace_G.has_value());
  if (a.workspace_G) {
    EXPECT_EQ(a.workspace_G->min(), b.workspace_G->min());
    EXPECT_EQ(a.workspace_G->max(), b.workspace_G->max());
  }
  EXPECT_EQ(a.voxel_m, b.voxel_m);
}

TEST(SessionDescriptionMessage, RoundTripWithEveryField) {
  const SessionDescription in = SomeSession();
  const auto bytes = EncodeSessionDescription(in);
  SessionDescription out;
  std::string error;
  ASSERT_TRUE(DecodeSessionDescription(bytes.data(), bytes.size(), &out, &error)) << error;
  ExpectSessionEqual(in, out);
}

TEST(SessionDescriptionMessage, RoundTripWithoutTheOptionalFields) {
  SessionDescription in;
  in.claw_name = "parallel";
  in.claw_text = "{\"finger_length_m\": 0.12}";
  in.software_version = SoftwareVersion();
  const auto bytes = EncodeSessionDescription(in);
  SessionDescription out = SomeSession();  // every field must be overwritten
  std::string error;
  ASSERT_TRUE(DecodeSessionDescription(bytes.data(), bytes.size(), &out, &error)) << error;
  ExpectSessionEqual(in, out);
  EXPECT_FALSE(out.intrinsics.has_value());
  EXPECT_FALSE(out.workspace_G.has_value());
  EXPECT_TRUE(out.T_C_B.matrix().isIdentity(0.0));
  EXPECT_EQ(out.software_version.rfind("graspfill ", 0), 0u) << out.software_version;
  EXPECT_GT(out.software_version.size(), std::string("graspfill ").size());
}

TEST(SessionDescriptionMessage, WireFormatIsTheGeneratedType) {
  const SessionDescription in = SomeSession();
  const auto bytes = EncodeSessionDescription(in);
  graspfill::session_description_t msg;
  ASSERT_EQ(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  // int8_t{...}: lcm-gen's constants have no definition to bind to.
  EXPECT_EQ(msg.claw_kind, int8_t{graspfill::session_description_t::CLAW_DESCRIPTION});
  EXPECT_EQ(msg.claw_name, "franka_hand");
  EXPECT_EQ(msg.has_intrinsics, 1);
  EXPECT_EQ(msg.width, 320);
  EXPECT_EQ(msg.fy, 291.25);
  EXPECT_EQ(msg.has_workspace_box, 1);
  EXPECT_EQ(msg.workspace_min[1], -0.06);
  EXPECT_EQ(msg.workspace_max[2], 0.2);
  EXPECT_EQ(msg.voxel_m, 0.002);
  EXPECT_NEAR(msg.T_C_B_position[2], 0.83, 1e-15);
  const Eigen::Quaterniond q(SomePose().rotation());
  EXPECT_NEAR(std::abs(msg.T_C_B_orientation[0]), std::abs(q.w()), 1e-12);
}

TEST(SessionDescriptionMessage, EncodeRejectsWhatWouldNotDecode) {
  auto expect_throw = [](const SessionDescription& s, const std::string& what) {
    try {
      EncodeSessionDescription(s);
      ADD_FAILURE() << "no exception, expected '" << what << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  SessionDescription s = SomeSession();
  s.claw_name.clear();
  expect_throw(s, "empty claw_name");
  s = SomeSession();
  s.T_C_B.translation().x() = kInf;
  expect_throw(s, "T_C_B is not finite");
  s = SomeSession();
  s.intrinsics->width = 0;
  expect_throw(s, "intrinsics override size 0x240");
  s = SomeSession();
  s.intrinsics->fx = -1.0;
  expect_throw(s, "focal length");
  s = SomeSession();
  s.workspace_G->max().z() = -1.0;
  expect_throw(s, "min < max");
  s = SomeSession();
  s.voxel_m = -0.001;
  expect_throw(s, "voxel_m");
  s.voxel_m = std::nan("");
  expect_throw(s, "voxel_m");
}

// Each field of a well-formed message set to a bad value, one at a time.
TEST(SessionDescriptionMessage, RejectsBadContent) {
  SessionDescription out;
  std::string error;
  auto decode = [&](const graspfill::session_description_t& msg) {
    const auto bytes = Encode(msg);
    return DecodeSessionDescription(bytes.data(), bytes.size(), &out, &error);
  };
  auto good = [] {
    graspfill::session_description_t msg{};
    msg.claw_name = "three-finger";
    msg.T_C_B_orientation[0] = 1.0;
    return msg;
  };
  ASSERT_TRUE(decode(good())) << error;

  auto msg = good();
  msg.claw_kind = 3;
  EXPECT_FALSE(decode(msg));
  EXPECT_NE(error.find("unknown claw_kind 3"), std::string::npos) << error;
  msg = good();
  msg.claw_name = "";
  EXPECT_FALSE(decode(msg));
  EXPECT_NE(error.find("empty claw_name"), std::string::npos) << error;
  msg = good();
  msg.T_C_B_orientation[0] = 0.9;
  EXPECT_FALSE(decode(msg));
  EXPECT_NE(error.find("T_C_B: orientation is not a unit quaternion"), std::string::npos) << error;
  msg = good();
  msg.T_C_B_position[1] = std::nan("");
  EXPECT_FALSE(decode(msg));
  EXPECT_NE(error.find("T_C_B: pose is not finite"), std::string::npos) << error;
  msg = good();
  msg.has_intrinsics = 2;
  EXPECT_FALSE(decode(msg));
  EXPECT_NE(error.find("must be 0 or 1"), std::string::npos) << error;
  msg = good();
  msg.has_intrinsics = 1;  // and a 0 x 0 image
  EXPECT_FALSE(decode(msg));
  EXPECT_NE(error.find("intrinsics override size 0x0"), std::string::npos) << error;
  msg.width = 4096;
  msg.height = 4097;  // one row over 2^24 pixels
  msg.fx = msg.fy = 500.0;
  EXPECT_FALSE(decode(msg));
  msg.height = 480;
  msg.width = 640;
  EXPECT_TRUE(decode(msg)) << error;
  msg.cx = kInf;
  EXPECT_FALSE(decode(msg));
  EXPECT_NE(error.find("bad intrinsics override"), std::string::npos) << error;
  msg = good();
  msg.has_workspace_box = 1;  // min == max == 0
  EXPECT_FALSE(decode(msg));
  EXPECT_NE(error.find("min < max"), std::string::npos) << error;
  msg.workspace_min[0] = msg.workspace_min[1] = msg.workspace_min[2] = -0.1;
  msg.workspace_max[0] = msg.workspace_max[1] = msg.workspace_max[2] = 0.1;
  EXPECT_TRUE(decode(msg)) << error;
  msg.workspace_max[1] = kInf;
  EXPECT_FALSE(decode(msg));
  msg = good();
  msg.voxel_m = -1e-3;
  EXPECT_FALSE(decode(msg));
  EXPECT_NE(error.find("voxel_m"), std::string::npos) << error;
  msg.voxel_m = kInf;
  EXPECT_FALSE(decode(msg));
}

// Issue 36: a claw name from the bus or a log was joined into a path and
// written to. It is a name: the decoder refuses anything else, with its
// own reason.
TEST(SessionDescriptionMessage, ClawNamesAreNamesNotPaths) {
  for (const std::string& bad : std::vector<std::string>{"../../victim", "/tmp/victim", "a/b", "..", ".",
                                                         "a\\b", "tab\there", std::string(257, 'x')}) {
    SCOPED_TRACE(bad);
    EXPECT_FALSE(IsPlainClawName(bad));
    graspfill::session_description_t msg{};
    msg.claw_kind = graspfill::session_description_t::CLAW_DESCRIPTION;
    msg.claw_name = bad;
    msg.T_C_B_orientation[0] = 1.0;
    const auto bytes = Encode(msg);
    SessionDescription out;
    std::string error;
    MessageError reason = MessageError::kNone;
    EXPECT_FALSE(DecodeSessionDescription(bytes.data(), bytes.size(), &out, &error, &reason));
    EXPECT_EQ(reason, MessageError::kBadClawName);
    EXPECT_NE(error.find("is not a plain name"), std::string::npos) << error;
    EXPECT_EQ(error.find('\t'), std::string::npos) << "control characters are escaped";
    SessionDescription session = SomeSession();
    session.claw_name = bad;
    EXPECT_THROW(EncodeSessionDescription(session), std::invalid_argument);
  }
  for (const std::string& good : std::vector<std::string>{"franka_hand", "Robotiq 3F v2", "three-finger",
                                                          "a..b", "x.json", std::string(256, 'x')}) {
    EXPECT_TRUE(IsPlainClawName(good)) << good;
  }
  EXPECT_STREQ(MessageErrorName(MessageError::kBadClawName), "bad_claw_name");
  EXPECT_EQ(MessageErrorFromName("claw_unloadable"), MessageError::kClawUnloadable);
  EXPECT_EQ(MessageErrorFromName("out_of_limits"), MessageError::kOutOfLimits);
}

// Issue 36: the bus gave a box of +-1e300 m and a voxel of 1 m where the
// config file allows -2..2 m and 0.5..10 mm. The limits are
// session_limits.hpp's, the config file's.
TEST(SessionDescriptionMessage, WithinLimitsIsTheConfigFilesRange) {
  std::string why;
  EXPECT_TRUE(SessionWithinLimits(SomeSession(), &why)) << why;
  SessionDescription s = SomeSession();
  s.voxel_m = 0.0;  // the receiver's default
  EXPECT_TRUE(SessionWithinLimits(s, &why)) << why;
  s.voxel_m = 1.0;
  EXPECT_FALSE(SessionWithinLimits(s, &why));
  EXPECT_NE(why.find("voxel of 1 m, outside 0.0005..0.01 m"), std::string::npos) << why;
  s.voxel_m = kMinVoxelM * 0.99;
  EXPECT_FALSE(SessionWithinLimits(s, &why));
  s.voxel_m = kMaxVoxelM;
  EXPECT_TRUE(SessionWithinLimits(s, &why)) << why;
  s = SomeSession();
  s.workspace_G = Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-1e300), Eigen::Vector3d::Constant(1e300));
  EXPECT_FALSE(SessionWithinLimits(s, &why));
  EXPECT_NE(why.find("workspace box with x -1e+300 m, outside -2..2 m"), std::string::npos) << why;
  s.workspace_G = Eigen::AlignedBox3d(Eigen::Vector3d(-2, -2, -2), Eigen::Vector3d(2, 2, 2.0001));
  EXPECT_FALSE(SessionWithinLimits(s, &why));
  EXPECT_NE(why.find("z 2.0001"), std::string::npos) << why;
  s.workspace_G->max().z() = kMaxWorkspaceM;
  EXPECT_TRUE(SessionWithinLimits(s, &why)) << why;
  s = SomeSession();
  s.T_C_B.translation().y() = -10.5;
  EXPECT_FALSE(SessionWithinLimits(s, &why));
  EXPECT_NE(why.find("T_C_B"), std::string::npos) << why;
}

TEST(SessionDescriptionMessage, RejectsMalformedBytes) {
  const auto bytes = EncodeSessionDescription(SomeSession());
  SessionDescription out;
  std::string error;
  for (size_t n = 0; n < bytes.size(); ++n) {
    EXPECT_FALSE(DecodeSessionDescription(bytes.data(), n, &out, &error)) << n;
  }
  auto longer = bytes;
  longer.push_back(0);
  EXPECT_FALSE(DecodeSessionDescription(longer.data(), longer.size(), &out, &error));
  EXPECT_NE(error.find("malformed"), std::string::npos) << error;
  // The first string's length (software_version) sits after the hash and
  // utime; forge lengths the generated decoder would trust.
  constexpr size_t kVersionLengthOffset = 8 + 8;
  for (uint32_t forged : {0xffffffffu, 0x7fffffffu, 0u, 0x10000u}) {
    auto bad = bytes;
    PokeInt32(&bad, kVersionLengthOffset, forged);
    EXPECT_FALSE(DecodeSessionDescription(bad.data(), bad.size(), &out, &error)) << forged;
    EXPECT_NE(error.find("malformed"), std::string::npos) << error;
  }
  // The claw text's length, after version, kind and name.
  const size_t text_length_offset = kVersionLengthOffset + 4 + SomeSession().software_version.size() + 1 + 1 +
                                    4 + SomeSession().claw_name.size() + 1;
  auto bad = bytes;
  PokeInt32(&bad, text_length_offset, 0x7ffffff0u);
  EXPECT_FALSE(DecodeSessionDescription(bad.data(), bad.size(), &out, &error));
  EXPECT_NE(error.find("malformed"), std::string::npos) << error;
  // Another type's bytes.
  const auto status = EncodeModuleStatus(ModuleStatus{});
  EXPECT_FALSE(DecodeSessionDescription(status.data(), status.size(), &out, &error));
  EXPECT_FALSE(DecodeSessionDescription(nullptr, 4, &out, &error));
  EXPECT_FALSE(DecodeSessionDescription(bytes.data(), bytes.size(), nullptr, &error));
}

TEST(SessionDescriptionMessage, ChannelNameDefault) {
  EXPECT_EQ(ChannelNames{}.session, "GRASPFILL_SESSION");
}

}  // namespace
}  // namespace graspfill::io

// ---- Issue 12: intrinsics, depth scale and timestamps in range, reasons ----

namespace graspfill::io {
namespace {

std::vector<uint8_t> DepthWith(double fx, double fy, double cx, double cy, double scale, int64_t utime) {
  graspfill::depth_image_t msg{};
  msg.utime = utime;
  msg.width = 4;
  msg.height = 2;
  msg.fx = fx;
  msg.fy = fy;
  msg.cx = cx;
  msg.cy = cy;
  msg.depth_scale = scale;
  msg.encoding = graspfill::depth_image_t::RAW16;
  msg.num_bytes = 16;
  msg.data.assign(16, 1);
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// fx = fy = 1e-300 made the claw cut-out cast infinite rays (Embree
// aborted); cx = 1e308 and fx = 1e300 overflowed float -> int in the crop.
TEST(DepthImageMessage, IntrinsicsOutOfRangeAreRejectedWithAReason) {
  DepthFrame out;
  std::string error;
  MessageError reason = MessageError::kNone;
  auto good = DepthWith(500, 500, 2, 1, 0.001, 10);
  ASSERT_TRUE(DecodeDepthImage(good.data(), good.size(), &out, &error, &reason)) << error;
  EXPECT_EQ(reason, MessageError::kNone);
  struct Case {
    double fx, fy, cx, cy;
  };
  for (const Case& c : {Case{1e-300, 1e-300, 2, 1}, Case{1e300, 500, 2, 1}, Case{500, 500, 1e308, 1},
                        Case{500, 500, 2, -1e308}, Case{0.5, 500, 2, 1}, Case{500, 2e5, 2, 1},
                        Case{500, 500, 9, 1}, Case{500, 500, 2, std::nan("")}}) {
    const auto bytes = DepthWith(c.fx, c.fy, c.cx, c.cy, 0.001, 10);
    EXPECT_FALSE(DecodeDepthImage(bytes.data(), bytes.size(), &out, &error, &reason)) << c.fx << " " << c.cx;
    EXPECT_EQ(reason, MessageError::kBadIntrinsics) << error;
    EXPECT_NE(error.find("bad intrinsics"), std::string::npos) << error;
  }
  for (double scale : {1e-300, 10.0, -1.0}) {
    const auto bytes = DepthWith(500, 500, 2, 1, scale, 10);
    EXPECT_FALSE(DecodeDepthImage(bytes.data(), bytes.size(), &out, &error, &reason));
    EXPECT_EQ(reason, MessageError::kBadDepthScale) << error;
  }
  for (int64_t utime : {INT64_MIN, int64_t{-1}, INT64_MAX, kMaxUtime + 1}) {
    const auto bytes = DepthWith(500, 500, 2, 1, 0.001, utime);
    EXPECT_FALSE(DecodeDepthImage(bytes.data(), bytes.size(), &out, &error, &reason));
    EXPECT_EQ(reason, MessageError::kBadTimestamp) << error;
  }
  const auto truncated = std::vector<uint8_t>(good.begin(), good.end() - 1);
  EXPECT_FALSE(DecodeDepthImage(truncated.data(), truncated.size(), &out, &error, &reason));
  EXPECT_EQ(reason, MessageError::kMalformed);
  EXPECT_STREQ(MessageErrorName(MessageError::kBadIntrinsics), "bad_intrinsics");
}

// Gripper states at INT64_MIN / INT64_MAX overflowed the interpolation.
TEST(GripperStateMessage, UtimeOutOfRangeIsRejected) {
  GripperState state;
  GripperState out;
  std::string error;
  MessageError reason = MessageError::kNone;
  for (int64_t utime : {INT64_MIN, int64_t{-5}, INT64_MAX}) {
    state.utime = utime;
    const auto bytes = EncodeGripperState(state);
    EXPECT_FALSE(
        DecodeGripperState(bytes.data(), bytes.size(), Eigen::Isometry3d::Identity(), &out, &error, &reason));
    EXPECT_EQ(reason, MessageError::kBadTimestamp) << error;
  }
  state.utime = 1700000000000000;
  const auto bytes = EncodeGripperState(state);
  EXPECT_TRUE(
      DecodeGripperState(bytes.data(), bytes.size(), Eigen::Isometry3d::Identity(), &out, &error, &reason));
  EXPECT_EQ(out.utime, state.utime);
  graspfill::gripper_state_t msg{};
  ASSERT_GT(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  msg.orientation[0] = 2.0;
  std::vector<uint8_t> bad(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bad.data(), 0, static_cast<int>(bad.size()));
  EXPECT_FALSE(
      DecodeGripperState(bad.data(), bad.size(), Eigen::Isometry3d::Identity(), &out, &error, &reason));
  EXPECT_EQ(reason, MessageError::kBadPose);
}

TEST(SessionDescriptionMessage, IntrinsicsOverrideOutOfRangeIsRefused) {
  SessionDescription s;
  s.claw_name = "three-finger";
  s.intrinsics = CameraIntrinsics{640, 480, 1e-300, 1e-300, 320, 240};
  EXPECT_THROW(EncodeSessionDescription(s), std::invalid_argument);
  s.intrinsics = CameraIntrinsics{640, 480, 500, 500, 1e308, 240};
  EXPECT_THROW(EncodeSessionDescription(s), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::io
