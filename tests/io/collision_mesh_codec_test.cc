// SPDX-License-Identifier: BSD-3-Clause
// collision_mesh_t: a mesh comes back exactly; every truncation, a trailing
// byte, a count beyond the bytes and each out-of-range field is refused
// with its reason, without a crash.
#include "graspfill/io/collision_mesh_message.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace graspfill::io {
namespace {

// A tetrahedron with a pose, a hull, a deviation.
CollisionMeshMessage Tetrahedron() {
  CollisionMeshMessage m;
  m.utime = 1700000000123456;
  m.seq = 42;
  m.grasp_id = 7;
  m.frame_name = "gripper";
  m.T_C_G =
      Eigen::Translation3d(0.1, -0.2, 0.6) * Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized());
  m.mesh.vertices = {{0, 0, 0}, {0.05f, 0, 0}, {0, 0.05f, 0}, {0, 0, 0.05f}};
  m.mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  m.kind = CollisionMeshKind::kConvexHull;
  m.watertight = true;
  m.deviation_m = 0.00042;
  return m;
}

// Offsets into Tetrahedron()'s encoding (collision_mesh_t.lcm's layout).
constexpr size_t kNameAt = 32;               // hash, utime, seq, grasp_id
constexpr size_t kPoseAt = kNameAt + 4 + 8;  // "gripper" and its NUL
constexpr size_t kKindAt = kPoseAt + 7 * 8;
constexpr size_t kWatertightAt = kKindAt + 1;
constexpr size_t kDeviationAt = kWatertightAt + 1;
constexpr size_t kNumVerticesAt = kDeviationAt + 4;
constexpr size_t kNumTrianglesAt = kNumVerticesAt + 4 + 4 * 12;
constexpr size_t kFirstTriangleAt = kNumTrianglesAt + 4;

void PutBigEndian(std::vector<uint8_t>* bytes, size_t at, uint64_t value, int width) {
  for (int i = 0; i < width; ++i) {
    (*bytes)[at + i] = static_cast<uint8_t>(value >> (8 * (width - 1 - i)));
  }
}

void PutDouble(std::vector<uint8_t>* bytes, size_t at, double v) {
  uint64_t u;
  std::memcpy(&u, &v, sizeof(u));
  PutBigEndian(bytes, at, u, 8);
}

// Decodes `bytes` expecting a refusal for `reason`; `out` stays as it was.
void ExpectRefused(const std::vector<uint8_t>& bytes, MessageError reason, const std::string& says) {
  CollisionMeshMessage out;
  out.seq = -5;
  std::string error;
  MessageError why = MessageError::kNone;
  EXPECT_FALSE(DecodeCollisionMesh(bytes.data(), bytes.size(), &out, &error, &why));
  EXPECT_EQ(why, reason) << error;
  EXPECT_NE(error.find(says), std::string::npos) << error;
  EXPECT_EQ(out.seq, -5);
}

TEST(CollisionMeshCodec, RoundTripIsExact) {
  const CollisionMeshMessage in = Tetrahedron();
  const std::vector<uint8_t> bytes = EncodeCollisionMesh(in);
  ASSERT_EQ(bytes.size(), kFirstTriangleAt + 4 * 12);  // the layout the offsets assume
  CollisionMeshMessage out;
  std::string error;
  MessageError reason = MessageError::kBadValue;
  ASSERT_TRUE(DecodeCollisionMesh(bytes.data(), bytes.size(), &out, &error, &reason)) << error;
  EXPECT_EQ(reason, MessageError::kNone);
  EXPECT_EQ(out.utime, in.utime);
  EXPECT_EQ(out.seq, in.seq);
  EXPECT_EQ(out.grasp_id, in.grasp_id);
  EXPECT_EQ(out.frame_name, in.frame_name);
  EXPECT_TRUE(out.T_C_G.isApprox(in.T_C_G, 1e-12));
  EXPECT_EQ(out.mesh.vertices, in.mesh.vertices);
  EXPECT_EQ(out.mesh.triangles, in.mesh.triangles);
  EXPECT_EQ(out.kind, CollisionMeshKind::kConvexHull);
  EXPECT_TRUE(out.watertight);
  EXPECT_EQ(out.deviation_m, static_cast<double>(static_cast<float>(in.deviation_m)));
  // The other kind and flag too.
  CollisionMeshMessage decimated = in;
  decimated.kind = CollisionMeshKind::kDecimated;
  decimated.watertight = false;
  const std::vector<uint8_t> b2 = EncodeCollisionMesh(decimated);
  ASSERT_TRUE(DecodeCollisionMesh(b2.data(), b2.size(), &out, &error)) << error;
  EXPECT_EQ(out.kind, CollisionMeshKind::kDecimated);
  EXPECT_FALSE(out.watertight);
}

TEST(CollisionMeshCodec, EveryTruncationAndATrailingByteAreMalformed) {
  std::vector<uint8_t> bytes = EncodeCollisionMesh(Tetrahedron());
  for (size_t n = 0; n < bytes.size(); ++n) {
    CollisionMeshMessage out;
    MessageError why = MessageError::kNone;
    EXPECT_FALSE(DecodeCollisionMesh(bytes.data(), n, &out, nullptr, &why)) << n << " bytes";
    EXPECT_EQ(why, MessageError::kMalformed) << n << " bytes";
  }
  bytes.push_back(0);
  ExpectRefused(bytes, MessageError::kMalformed, "malformed");
  EXPECT_FALSE(DecodeCollisionMesh(nullptr, 10, nullptr, nullptr));
}

TEST(CollisionMeshCodec, CountsAndStringsBeyondTheBytesAreMalformed) {
  const std::vector<uint8_t> good = EncodeCollisionMesh(Tetrahedron());
  for (const uint32_t count : {0x7fffffffu, 0x80000000u, 5u, 0xffffffffu}) {
    std::vector<uint8_t> b = good;
    PutBigEndian(&b, kNumVerticesAt, count, 4);
    ExpectRefused(b, MessageError::kMalformed, "malformed");
    b = good;
    PutBigEndian(&b, kNumTrianglesAt, count, 4);
    ExpectRefused(b, MessageError::kMalformed, "malformed");
  }
  std::vector<uint8_t> b = good;
  PutBigEndian(&b, kNameAt, 0x7fffffff, 4);  // the frame name's length
  ExpectRefused(b, MessageError::kMalformed, "malformed");
  b = good;
  PutBigEndian(&b, kNameAt, 0, 4);
  ExpectRefused(b, MessageError::kMalformed, "malformed");
  b = good;
  b[kNameAt + 4 + 2] = 0;  // a NUL inside the name
  ExpectRefused(b, MessageError::kMalformed, "malformed");
  b = good;
  b[0] ^= 1;  // another type's hash
  ExpectRefused(b, MessageError::kMalformed, "malformed");
}

TEST(CollisionMeshCodec, FieldsOutOfRangeAreRefusedWithTheirReason) {
  const std::vector<uint8_t> good = EncodeCollisionMesh(Tetrahedron());
  std::vector<uint8_t> b = good;
  PutBigEndian(&b, kFirstTriangleAt + 4, 4, 4);  // vertex 4 of 4
  ExpectRefused(b, MessageError::kBadValue, "outside the 4 vertices");
  b = good;
  PutBigEndian(&b, kFirstTriangleAt, 0xffffffff, 4);  // -1
  ExpectRefused(b, MessageError::kBadValue, "outside the 4 vertices");
  b = good;
  b[kKindAt] = 2;
  ExpectRefused(b, MessageError::kBadValue, "unknown kind 2");
  b = good;
  b[kWatertightAt] = 3;
  ExpectRefused(b, MessageError::kBadValue, "watertight must be 0 or 1");
  b = good;
  PutBigEndian(&b, kDeviationAt, 0x7fc00000, 4);  // NaN
  ExpectRefused(b, MessageError::kBadValue, "deviation_m");
  b = good;
  PutBigEndian(&b, kDeviationAt, 0xbf800000, 4);  // -1
  ExpectRefused(b, MessageError::kBadValue, "deviation_m");
  b = good;
  PutBigEndian(&b, kNumVerticesAt + 4, 0x7f800000, 4);  // the first vertex's x: inf
  ExpectRefused(b, MessageError::kBadValue, "vertex is not finite");
  b = good;
  PutDouble(&b, kPoseAt + 3 * 8, 2.0);  // w = 2
  ExpectRefused(b, MessageError::kBadPose, "not a unit quaternion");
  b = good;
  PutDouble(&b, kPoseAt, std::numeric_limits<double>::quiet_NaN());
  ExpectRefused(b, MessageError::kBadPose, "not finite");
  b = good;
  PutBigEndian(&b, 8, static_cast<uint64_t>(-1), 8);  // utime -1
  ExpectRefused(b, MessageError::kBadTimestamp, "utime");
}

TEST(CollisionMeshCodec, TheEncoderRefusesAnInconsistentMesh) {
  CollisionMeshMessage m = Tetrahedron();
  m.mesh.triangles.push_back({0, 1, 9});
  EXPECT_THROW(EncodeCollisionMesh(m), std::invalid_argument);
  m = Tetrahedron();
  m.mesh.vertices[1].x() = std::nanf("");
  EXPECT_THROW(EncodeCollisionMesh(m), std::invalid_argument);
  m = Tetrahedron();
  m.deviation_m = -0.001;
  EXPECT_THROW(EncodeCollisionMesh(m), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::io
