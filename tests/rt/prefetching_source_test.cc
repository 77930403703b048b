// SPDX-License-Identifier: BSD-3-Clause
#include "sources/prefetching_source.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>

namespace graspfill::rt {
namespace {

// Counts up: depth frames with utime 0..n-1, every third one bad.
class CountingSource : public FrameSource {
 public:
  explicit CountingSource(int n, bool throw_at_end = false) : n_(n), throw_at_end_(throw_at_end) {}
  FrameResult Next(SourceEvent* e) override {
    if (i_ == n_) {
      if (throw_at_end_) throw std::runtime_error("disk on fire");
      return FrameResult::kEndOfStream;
    }
    e->kind = SourceEvent::Kind::kDepth;
    e->depth.utime = i_;
    e->depth.depth_m.assign(16, static_cast<float>(i_));
    e->error = i_ % 3 == 2 ? "bad " + std::to_string(i_) : "";
    return i_++ % 3 == 2 ? FrameResult::kBadFrame : FrameResult::kOk;
  }

 private:
  int n_, i_{0};
  bool throw_at_end_;
};

TEST(PrefetchingSource, SameEventsInSameOrderThenStickyEnd) {
  PrefetchingSource source(std::make_unique<CountingSource>(100), 4);
  SourceEvent e;
  for (int i = 0; i < 100; ++i) {
    const FrameResult r = source.Next(&e);
    ASSERT_EQ(r, i % 3 == 2 ? FrameResult::kBadFrame : FrameResult::kOk) << i;
    EXPECT_EQ(e.depth.utime, i);
    EXPECT_EQ(e.depth.depth_m[15], static_cast<float>(i));
  }
  EXPECT_EQ(source.Next(&e), FrameResult::kEndOfStream);
  EXPECT_EQ(source.Next(&e), FrameResult::kEndOfStream);
}

TEST(PrefetchingSource, ReaderExceptionBecomesABadEventThenEnd) {
  PrefetchingSource source(std::make_unique<CountingSource>(2, true), 2);
  SourceEvent e;
  EXPECT_EQ(source.Next(&e), FrameResult::kOk);
  EXPECT_EQ(source.Next(&e), FrameResult::kOk);
  EXPECT_EQ(source.Next(&e), FrameResult::kBadFrame);
  EXPECT_EQ(e.error, "disk on fire");
  EXPECT_EQ(source.Next(&e), FrameResult::kEndOfStream);
}

TEST(PrefetchingSource, DestroyedEarlyWithoutDeadlock) {
  PrefetchingSource source(std::make_unique<CountingSource>(1000), 2);
  SourceEvent e;
  source.Next(&e);
}  // the reader is blocked on a full queue here: the destructor must wake it

}  // namespace
}  // namespace graspfill::rt
