// SPDX-License-Identifier: BSD-3-Clause
// Reads (and decodes) events of another source ahead on its own thread, so
// that log decoding overlaps the pipeline's work on the caller's thread.
// Events come out in the wrapped source's order, unchanged.
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "sources/frame_source.hpp"

namespace graspfill::rt {

class PrefetchingSource : public FrameSource {
 public:
  /// Starts reading `source` (owned) ahead by up to `depth` events.
  PrefetchingSource(std::unique_ptr<FrameSource> source, int depth = 8);
  /// Stops the reader thread.
  ~PrefetchingSource() override;
  PrefetchingSource(const PrefetchingSource&) = delete;
  PrefetchingSource& operator=(const PrefetchingSource&) = delete;

  /// Next event of the wrapped source; waits for the reader when empty.
  /// Swaps buffers with *event, so steady-state reading allocates nothing.
  FrameResult Next(SourceEvent* event) override;

  /// The wrapped source; only safe to use once Next returned kEndOfStream.
  FrameSource& wrapped() { return *source_; }

 private:
  void ReaderLoop();

  std::unique_ptr<FrameSource> source_;
  std::vector<SourceEvent> slots_;  // ring
  std::vector<FrameResult> results_;
  size_t head_{0}, count_{0};
  bool ended_{false};
  bool stop_{false};
  bool failed_{false};  // the wrapped source threw (reader thread only)
  std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  std::thread reader_;
};

}  // namespace graspfill::rt
