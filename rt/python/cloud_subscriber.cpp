// SPDX-License-Identifier: BSD-3-Clause
#include "cloud_subscriber.hpp"

#include <new>
#include <stdexcept>

#include "graspfill/io/cloud_chunks.hpp"
#include "graspfill/io/messages.hpp"

namespace graspfill::python {

CloudSubscriber::CloudSubscriber(const std::string& url, const std::string& channel) {
  if (channel.empty()) throw std::invalid_argument("Subscriber: the channel is empty");
  // NULL, not "": LCM then takes LCM_DEFAULT_URL, else its default.
  lcm_ = lcm_create(url.empty() ? nullptr : url.c_str());
  if (lcm_ == nullptr) {
    throw std::runtime_error("Subscriber: LCM cannot be set up with URL '" +
                             (url.empty() ? std::string("(LCM's default)") : url) + "'");
  }
  subscription_ = lcm_subscribe(lcm_, channel.c_str(), &CloudSubscriber::OnMessage, this);
  if (subscription_ == nullptr) {
    lcm_destroy(lcm_);
    lcm_ = nullptr;
    throw std::runtime_error("Subscriber: LCM cannot subscribe to '" + channel + "'");
  }
}

CloudSubscriber::~CloudSubscriber() { Close(); }

void CloudSubscriber::OnMessage(const lcm_recv_buf_t* buffer, const char* /*channel*/, void* self) {
  auto* subscriber = static_cast<CloudSubscriber*>(self);
  try {
    const auto* bytes = static_cast<const uint8_t*>(buffer->data);
    subscriber->received_.emplace_back(bytes, bytes + buffer->data_size);
  } catch (const std::bad_alloc&) {
    subscriber->dropped_for_memory_ = true;  // reported by DecodeNext
  }
}

CloudSubscriber::WaitResult CloudSubscriber::DecodeNext(ObjectCloud* cloud, std::string* error) {
  if (dropped_for_memory_) {
    dropped_for_memory_ = false;
    ++bad_messages_;
    *error = "a message was dropped: out of memory copying it";
    return WaitResult::kBadMessage;
  }
  // Slices (udpm) are joined first; a whole object_cloud_t passes through.
  while (!received_.empty()) {
    const std::vector<uint8_t> payload = std::move(received_.front());
    received_.pop_front();
    const io::CloudChunkAssembler::Result joined = slices_.Add(payload.data(), payload.size(), error);
    if (joined == io::CloudChunkAssembler::Result::kPending ||
        joined == io::CloudChunkAssembler::Result::kRepeat) {
      continue;
    }
    if (joined != io::CloudChunkAssembler::Result::kComplete ||
        !io::DecodeObjectCloud(slices_.cloud().data(), slices_.cloud().size(), cloud, error)) {
      ++bad_messages_;
      return WaitResult::kBadMessage;
    }
    return WaitResult::kCloud;
  }
  return WaitResult::kTimeout;  // slices taken, the cloud not whole yet
}

CloudSubscriber::WaitResult CloudSubscriber::Wait(int timeout_ms, ObjectCloud* cloud, std::string* error) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (lcm_ == nullptr) throw std::runtime_error("Subscriber: closed");
  if (received_.empty() && !dropped_for_memory_) {
    if (ended_) return WaitResult::kEnded;
    if (lcm_handle_timeout(lcm_, timeout_ms < 0 ? 0 : timeout_ms) < 0) {
      ended_ = true;  // what was handled before is still given out
    }
  }
  // A message on no channel of ours is handled without a call of OnMessage.
  if (received_.empty() && !dropped_for_memory_) return ended_ ? WaitResult::kEnded : WaitResult::kTimeout;
  const WaitResult result = DecodeNext(cloud, error);
  // The last slices of a log that ended: nothing more comes.
  return result == WaitResult::kTimeout && ended_ ? WaitResult::kEnded : result;
}

void CloudSubscriber::Close() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (lcm_ == nullptr) return;
  lcm_unsubscribe(lcm_, subscription_);
  lcm_destroy(lcm_);
  lcm_ = nullptr;
  subscription_ = nullptr;
  received_.clear();
}

bool CloudSubscriber::closed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return lcm_ == nullptr;
}

int64_t CloudSubscriber::bad_messages() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return bad_messages_;
}

}  // namespace graspfill::python
