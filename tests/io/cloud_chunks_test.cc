// SPDX-License-Identifier: BSD-3-Clause
// A model in one-datagram slices: cut, joined in any order, repeats
// ignored, a missing slice never completes, a newer cloud drops an
// unfinished one, malformed slices are rejected.
#include "graspfill/io/cloud_chunks.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>

#include <time.h>

#include <graspfill/object_cloud_chunk_t.hpp>

#include "graspfill/io/messages.hpp"

namespace graspfill::io {
namespace {

using Result = CloudChunkAssembler::Result;

// A cloud whose packed points do not deflate much (random positions), so
// that it takes several slices.
std::vector<uint8_t> EncodedCloud(int64_t seq, size_t num_points, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-0.05f, 0.05f);
  ObjectCloud cloud;
  cloud.utime = 1700000000000000 + seq;
  cloud.seq = seq;
  cloud.frame_name = "gripper";
  for (size_t i = 0; i < num_points; ++i) cloud.points_G.emplace_back(u(rng), u(rng), u(rng));
  return EncodeObjectCloud(cloud);
}

// Overwrites the big-endian int32 header field `i` of a slice (0:
// cloud_num_bytes, 1: crc, 2: num_chunks, 3: index, 4: offset, 5: num_bytes).
void PokeField(std::vector<uint8_t>* slice, size_t i, uint32_t value) {
  for (size_t b = 0; b < 4; ++b) (*slice)[24 + 4 * i + b] = static_cast<uint8_t>(value >> (24 - 8 * b));
}

Result Add(CloudChunkAssembler* a, const std::vector<uint8_t>& bytes, std::string* why = nullptr) {
  return a->Add(bytes.data(), bytes.size(), why);
}

TEST(CloudChunks, CutsIntoEqualOneDatagramSlicesThatDecodeAsTheLcmType) {
  const std::vector<uint8_t> cloud = EncodedCloud(7, 30000, 1);
  ASSERT_GT(cloud.size(), 2 * kCloudSliceBytes);  // three slices at least
  const auto slices = EncodeCloudChunks(cloud);
  const size_t n = (cloud.size() + kCloudSliceBytes - 1) / kCloudSliceBytes;
  ASSERT_EQ(slices.size(), n);
  size_t joined = 0;
  for (size_t i = 0; i < n; ++i) {
    graspfill::object_cloud_chunk_t msg;
    ASSERT_EQ(msg.decode(slices[i].data(), 0, static_cast<int>(slices[i].size())),
              static_cast<int>(slices[i].size()));
    EXPECT_LE(slices[i].size(), 65499u - 8u - 32u);  // LCM's one-datagram limit, a long channel name
    EXPECT_EQ(msg.seq, 7);
    EXPECT_EQ(msg.utime, 1700000000000000 + 7);
    EXPECT_EQ(msg.num_chunks, static_cast<int32_t>(n));
    EXPECT_EQ(msg.chunk_index, static_cast<int32_t>(i));
    EXPECT_EQ(msg.offset, static_cast<int32_t>(joined));
    EXPECT_TRUE(std::equal(msg.data.begin(), msg.data.end(), cloud.begin() + static_cast<long>(joined)));
    joined += msg.data.size();
    // Equal slices, the last no longer than the others.
    if (i + 1 < n) {
      EXPECT_EQ(msg.data.size(), (cloud.size() + n - 1) / n);
    }
  }
  EXPECT_EQ(joined, cloud.size());
  EXPECT_EQ(EncodeCloudChunks(cloud), slices);                      // deterministic
  EXPECT_EQ(EncodeCloudChunks(EncodedCloud(1, 10, 2)).size(), 1u);  // small: one slice
}

TEST(CloudChunks, JoinsSlicesInAnyOrderIntoTheSameBytes) {
  const std::vector<uint8_t> cloud = EncodedCloud(3, 4000, 3);
  auto slices = EncodeCloudChunks(cloud, 997);  // many slices
  ASSERT_GT(slices.size(), 20u);
  std::mt19937 rng(4);
  std::shuffle(slices.begin(), slices.end(), rng);
  CloudChunkAssembler a;
  for (size_t i = 0; i + 1 < slices.size(); ++i) ASSERT_EQ(Add(&a, slices[i]), Result::kPending) << i;
  ASSERT_EQ(Add(&a, slices.back()), Result::kComplete);
  EXPECT_EQ(a.cloud(), cloud);
  ObjectCloud decoded;
  std::string error;
  EXPECT_TRUE(DecodeObjectCloud(a.cloud().data(), a.cloud().size(), &decoded, &error)) << error;
  EXPECT_EQ(decoded.seq, 3);
  EXPECT_EQ(decoded.points_G.size(), 4000u);
}

TEST(CloudChunks, RepeatsAreIgnoredAndACloudIsGivenOnce) {
  const std::vector<uint8_t> cloud = EncodedCloud(5, 3000, 5);
  const auto slices = EncodeCloudChunks(cloud, 10000);
  ASSERT_GE(slices.size(), 2u);
  CloudChunkAssembler a;
  EXPECT_EQ(Add(&a, slices[0]), Result::kPending);
  EXPECT_EQ(Add(&a, slices[0]), Result::kRepeat);
  int completed = 0;
  // The whole cloud sent twice, as a publisher that repeats its slices.
  for (int copy = 0; copy < 2; ++copy) {
    for (const auto& s : slices) completed += Add(&a, s) == Result::kComplete ? 1 : 0;
  }
  EXPECT_EQ(completed, 1);
  EXPECT_EQ(a.cloud(), cloud);
  EXPECT_EQ(a.dropped_unfinished(), 0);
}

TEST(CloudChunks, AMissingSliceNeverCompletesAndTheNextCloudDropsIt) {
  const auto first = EncodeCloudChunks(EncodedCloud(1, 3000, 6), 10000);
  const std::vector<uint8_t> second_cloud = EncodedCloud(2, 3000, 7);
  const auto second = EncodeCloudChunks(second_cloud, 10000);
  CloudChunkAssembler a;
  for (size_t i = 0; i + 1 < first.size(); ++i) EXPECT_EQ(Add(&a, first[i]), Result::kPending);
  EXPECT_EQ(a.dropped_unfinished(), 0);
  Result last = Result::kPending;
  for (const auto& s : second) last = Add(&a, s);
  EXPECT_EQ(last, Result::kComplete);
  EXPECT_EQ(a.cloud(), second_cloud);
  EXPECT_EQ(a.dropped_unfinished(), 1);
  // The first cloud's late slice starts it again: never a mix of the two.
  EXPECT_EQ(Add(&a, first.back()), first.size() == 1 ? Result::kComplete : Result::kPending);
}

TEST(CloudChunks, ACloudWithAnEarlierCloudsSeqIsNotTakenForARepeat) {
  // A publisher restarted: seq 1 again, other points.
  const std::vector<uint8_t> a_cloud = EncodedCloud(1, 2000, 8), b_cloud = EncodedCloud(1, 2000, 9);
  CloudChunkAssembler a;
  for (const auto& s : EncodeCloudChunks(a_cloud, 5000)) Add(&a, s);
  ASSERT_EQ(a.cloud(), a_cloud);
  Result last = Result::kPending;
  for (const auto& s : EncodeCloudChunks(b_cloud, 5000)) last = Add(&a, s);
  EXPECT_EQ(last, Result::kComplete);
  EXPECT_EQ(a.cloud(), b_cloud);
}

TEST(CloudChunks, AWholeObjectCloudPassesThrough) {
  const std::vector<uint8_t> cloud = EncodedCloud(4, 100, 10);
  const auto pending = EncodeCloudChunks(EncodedCloud(3, 3000, 11), 5000);
  CloudChunkAssembler a;
  EXPECT_EQ(Add(&a, pending[0]), Result::kPending);
  EXPECT_EQ(Add(&a, cloud), Result::kComplete);
  EXPECT_EQ(a.cloud(), cloud);
  EXPECT_EQ(a.dropped_unfinished(), 1);
}

TEST(CloudChunks, MalformedMessagesAreRejectedWithAReason) {
  const std::vector<uint8_t> cloud = EncodedCloud(9, 3000, 12);
  const auto slices = EncodeCloudChunks(cloud, 4000);
  ASSERT_GE(slices.size(), 3u);
  const auto rejected = [](std::vector<uint8_t> bytes) {
    CloudChunkAssembler a;
    std::string why;
    const Result r = Add(&a, bytes, &why);
    EXPECT_NE(why.find("malformed"), std::string::npos) << why;
    return r == Result::kMalformed;
  };
  EXPECT_TRUE(rejected({}));
  EXPECT_TRUE(rejected({1, 2, 3}));
  EXPECT_TRUE(rejected(std::vector<uint8_t>(100, 0)));  // another type's hash
  EXPECT_TRUE(rejected(std::vector<uint8_t>(slices[1].begin(), slices[1].begin() + 30)));  // header cut
  EXPECT_TRUE(rejected(std::vector<uint8_t>(slices[1].begin(), slices[1].end() - 1)));     // data cut
  auto longer = slices[1];
  longer.push_back(0);
  EXPECT_TRUE(rejected(longer));
  const auto poked = [&](size_t field, uint32_t value) {
    auto s = slices[1];
    PokeField(&s, field, value);
    return s;
  };
  EXPECT_TRUE(rejected(poked(0, 0)));                                                 // an empty cloud
  EXPECT_TRUE(rejected(poked(0, 0x80000000u)));                                       // negative size
  EXPECT_TRUE(rejected(poked(0, static_cast<uint32_t>(kMaxChunkedCloudBytes + 1))));  // too large to allocate
  EXPECT_TRUE(rejected(poked(2, 0)));                                                 // no slices
  EXPECT_TRUE(rejected(poked(2, 0xffffffffu)));                                       // -1 slices
  EXPECT_TRUE(rejected(poked(3, static_cast<uint32_t>(slices.size()))));              // index past the last
  EXPECT_TRUE(rejected(poked(3, 0xffffffffu)));                                       // index -1
  EXPECT_TRUE(rejected(poked(4, 0)));            // offset not index * slice
  EXPECT_TRUE(rejected(poked(5, 0x7fffffffu)));  // num_bytes past the message
  // A slice whose bytes were changed: the joined cloud's CRC differs.
  CloudChunkAssembler a;
  auto corrupt = slices;
  corrupt[1].back() ^= 0x40;
  Result last = Result::kPending;
  std::string why;
  for (const auto& s : corrupt) last = Add(&a, s, &why);
  EXPECT_EQ(last, Result::kMalformed);
  EXPECT_NE(why.find("CRC"), std::string::npos) << why;
  // ... and the good slices of the same cloud then join.
  for (const auto& s : slices) last = Add(&a, s);
  EXPECT_EQ(last, Result::kComplete);
  EXPECT_EQ(a.cloud(), cloud);
}

double CpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

TEST(CloudChunks, HeadersClaimingHugeCloudsCostLittle) {
  // 49-byte slices of ever other clouds, each claiming 64 MiB in 1-byte
  // slices, alternating with a whole small cloud: each cleared and resized
  // a 64 MB slice table and the cloud (3.4 ms of CPU a message in Release,
  // found while writing fuzz_cloud_chunks; tests/fuzz/regressions/cloud_chunks/).
  const std::vector<uint8_t> small = EncodedCloud(1, 10, 14);
  auto slice = EncodeCloudChunks(small, 1).front();
  slice.resize(48 + 1);
  PokeField(&slice, 0, static_cast<uint32_t>(kMaxChunkedCloudBytes));
  PokeField(&slice, 2, static_cast<uint32_t>(kMaxChunkedCloudBytes));
  PokeField(&slice, 5, 1);
  CloudChunkAssembler a;
  const int n = 300;
  const double start = CpuSeconds();
  for (int i = 0; i < n; ++i) {
    slice[23] = static_cast<uint8_t>(i);  // seq: another cloud each time
    ASSERT_EQ(Add(&a, slice), Result::kPending);
    ASSERT_EQ(Add(&a, small), Result::kComplete);
  }
  const double per_message_s = (CpuSeconds() - start) / (2 * n);
  EXPECT_LT(per_message_s, 2e-4);  // a tenth of a 64 MB pass, even under ASan
  EXPECT_EQ(a.dropped_unfinished(), n);
  // ... and such a cloud still joins: its last slice after a repeat.
  const auto slices = EncodeCloudChunks(small, 7);
  for (const auto& s : slices) Add(&a, s);
  EXPECT_EQ(Add(&a, slices.front()), Result::kRepeat);
  EXPECT_EQ(a.cloud(), small);
}

TEST(CloudChunks, TheCutterRefusesWhatIsNotACloud) {
  EXPECT_THROW(EncodeCloudChunks(std::vector<uint8_t>(100, 0)), std::invalid_argument);
  EXPECT_THROW(EncodeCloudChunks({}), std::invalid_argument);
  EXPECT_THROW(EncodeCloudChunks(EncodedCloud(1, 10, 13), 0), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::io
