// SPDX-License-Identifier: BSD-3-Clause
// The pacer sends each cloud's slices in order, a gap apart, as many
// rounds as asked, from its own thread; what was queued goes out before it
// is destroyed; a full queue drops the oldest cloud.
#include "sinks/cloud_pacer.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "graspfill/io/cloud_chunks.hpp"
#include "graspfill/io/messages.hpp"

namespace graspfill::rt {
namespace {

using Clock = std::chrono::steady_clock;

std::vector<uint8_t> EncodedCloud(int64_t seq, size_t num_points) {
  std::mt19937 rng(static_cast<uint32_t>(seq));
  std::uniform_real_distribution<float> u(-0.05f, 0.05f);
  ObjectCloud cloud;
  cloud.seq = seq;
  cloud.frame_name = "gripper";
  for (size_t i = 0; i < num_points; ++i) cloud.points_G.emplace_back(u(rng), u(rng), u(rng));
  return io::EncodeObjectCloud(cloud);
}

struct Sent {
  std::string channel;
  std::vector<uint8_t> bytes;
  Clock::time_point at;
  std::thread::id thread;
};

class Recorder {
 public:
  CloudPacer::Send Sink() {
    return [this](const std::string& channel, const std::vector<uint8_t>& bytes) {
      std::lock_guard<std::mutex> lock(mutex_);
      sent_.push_back({channel, bytes, Clock::now(), std::this_thread::get_id()});
      return ok_;
    };
  }
  std::vector<Sent> sent() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return sent_;
  }
  bool ok_{true};

 private:
  mutable std::mutex mutex_;
  std::vector<Sent> sent_;
};

TEST(CloudPacer, SendsEachCloudsSlicesInRoundsAGapApartFromItsOwnThread) {
  const std::vector<uint8_t> cloud = EncodedCloud(1, 3000);
  CloudPacing pacing;
  pacing.slice_bytes = 4000;
  pacing.gap_ms = 4.0;
  pacing.copies = 2;
  const size_t n = io::EncodeCloudChunks(cloud, pacing.slice_bytes).size();
  ASSERT_GE(n, 3u);
  Recorder recorder;
  {
    CloudPacer pacer(pacing, recorder.Sink());
    const auto before = Clock::now();
    pacer.Submit("CLOUD", cloud);
    EXPECT_LT(Clock::now() - before,
              std::chrono::milliseconds(static_cast<int>(pacing.gap_ms)));  // never waits
    EXPECT_TRUE(pacer.Flush(5000));
    EXPECT_EQ(pacer.send_failures(), 0);
  }
  const std::vector<Sent> sent = recorder.sent();
  ASSERT_EQ(sent.size(), 2 * n);
  io::CloudChunkAssembler joined;
  int completed = 0;
  for (size_t i = 0; i < sent.size(); ++i) {
    EXPECT_EQ(sent[i].channel, "CLOUD");
    EXPECT_NE(sent[i].thread, std::this_thread::get_id());
    EXPECT_EQ(sent[i].bytes, sent[i % n].bytes);  // the second round repeats the first
    if (i > 0) {
      EXPECT_GE(sent[i].at - sent[i - 1].at, std::chrono::milliseconds(4));
    }
    completed +=
        joined.Add(sent[i].bytes.data(), sent[i].bytes.size()) == io::CloudChunkAssembler::Result::kComplete
            ? 1
            : 0;
  }
  EXPECT_EQ(completed, 1);
  EXPECT_EQ(joined.cloud(), cloud);
}

TEST(CloudPacer, WhatWasQueuedGoesOutBeforeItIsDestroyed) {
  CloudPacing pacing;
  pacing.gap_ms = 1.0;
  pacing.copies = 1;
  Recorder recorder;
  {
    CloudPacer pacer(pacing, recorder.Sink());
    for (int64_t seq = 1; seq <= 3; ++seq) pacer.Submit("CLOUD", EncodedCloud(seq, 100));
  }
  const std::vector<Sent> sent = recorder.sent();
  ASSERT_EQ(sent.size(), 3u);  // small clouds: one slice each
  io::CloudChunkAssembler joined;
  for (int64_t seq = 1; seq <= 3; ++seq) {
    const Sent& s = sent[static_cast<size_t>(seq - 1)];
    ASSERT_EQ(joined.Add(s.bytes.data(), s.bytes.size()), io::CloudChunkAssembler::Result::kComplete);
    ObjectCloud cloud;
    std::string error;
    ASSERT_TRUE(io::DecodeObjectCloud(joined.cloud().data(), joined.cloud().size(), &cloud, &error)) << error;
    EXPECT_EQ(cloud.seq, seq);
  }
}

TEST(CloudPacer, AFullQueueDropsTheOldestAndFailuresAreCounted) {
  CloudPacing pacing;
  pacing.gap_ms = 20.0;
  pacing.copies = 1;
  Recorder recorder;
  recorder.ok_ = false;
  CloudPacer pacer(pacing, recorder.Sink());
  // One goes out at once; the queue then holds kMaxQueued, and the rest
  // push out the oldest.
  const int64_t submitted = static_cast<int64_t>(CloudPacer::kMaxQueued) + 4;
  for (int64_t seq = 1; seq <= submitted; ++seq) pacer.Submit("CLOUD", EncodedCloud(seq, 50));
  ASSERT_TRUE(pacer.Flush(10000));
  const int64_t sent = static_cast<int64_t>(recorder.sent().size());
  EXPECT_GE(pacer.dropped(), 1);
  EXPECT_EQ(sent + pacer.dropped(), submitted);
  EXPECT_EQ(pacer.send_failures(), sent);
  // The newest always goes out.
  ObjectCloud last;
  io::CloudChunkAssembler joined;
  const std::vector<uint8_t> bytes = recorder.sent().back().bytes;
  ASSERT_EQ(joined.Add(bytes.data(), bytes.size()), io::CloudChunkAssembler::Result::kComplete);
  ASSERT_TRUE(io::DecodeObjectCloud(joined.cloud().data(), joined.cloud().size(), &last, nullptr));
  EXPECT_EQ(last.seq, submitted);
}

TEST(CloudPacer, RefusesAPacingThatCannotSend) {
  Recorder recorder;
  CloudPacing zero_slice;
  zero_slice.slice_bytes = 0;
  EXPECT_THROW(CloudPacer(zero_slice, recorder.Sink()), std::invalid_argument);
  CloudPacing no_copy;
  no_copy.copies = 0;
  EXPECT_THROW(CloudPacer(no_copy, recorder.Sink()), std::invalid_argument);
  CloudPacing negative_gap;
  negative_gap.gap_ms = -1.0;
  EXPECT_THROW(CloudPacer(negative_gap, recorder.Sink()), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::rt
