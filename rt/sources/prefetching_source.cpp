// SPDX-License-Identifier: BSD-3-Clause
#include "sources/prefetching_source.hpp"

#include <stdexcept>
#include <utility>

namespace graspfill::rt {

PrefetchingSource::PrefetchingSource(std::unique_ptr<FrameSource> source, int depth)
    : source_(std::move(source)) {
  if (!source_ || depth < 1) throw std::invalid_argument("PrefetchingSource: need a source and depth >= 1");
  slots_.resize(static_cast<size_t>(depth));
  results_.resize(static_cast<size_t>(depth));
  reader_ = std::thread(&PrefetchingSource::ReaderLoop, this);
}

PrefetchingSource::~PrefetchingSource() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  not_full_.notify_all();
  reader_.join();
}

void PrefetchingSource::ReaderLoop() {
  SourceEvent event;  // read outside the lock, then swapped into a slot
  for (;;) {
    FrameResult result = FrameResult::kEndOfStream;
    if (!failed_) {
      try {
        result = source_->Next(&event);
      } catch (const std::exception& e) {  // report it as a bad event, then end
        event.error = e.what();
        result = FrameResult::kBadFrame;
        failed_ = true;
      }
    }
    std::unique_lock<std::mutex> lock(mutex_);
    not_full_.wait(lock, [&] { return stop_ || count_ < slots_.size(); });
    if (stop_) return;
    const size_t tail = (head_ + count_) % slots_.size();
    std::swap(slots_[tail], event);
    results_[tail] = result;
    ++count_;
    if (result == FrameResult::kEndOfStream) ended_ = true;
    lock.unlock();
    not_empty_.notify_one();
    if (result == FrameResult::kEndOfStream) return;
  }
}

FrameResult PrefetchingSource::Next(SourceEvent* event) {
  std::unique_lock<std::mutex> lock(mutex_);
  not_empty_.wait(lock, [&] { return count_ > 0; });
  const FrameResult result = results_[head_];
  if (result == FrameResult::kEndOfStream) return result;  // stays queued: sticky end
  std::swap(*event, slots_[head_]);
  head_ = (head_ + 1) % slots_.size();
  --count_;
  lock.unlock();
  not_full_.notify_one();
  return result;
}

}  // namespace graspfill::rt
