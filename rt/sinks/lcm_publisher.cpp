// SPDX-License-Identifier: BSD-3-Clause
#include "sinks/lcm_publisher.hpp"

#include "sinks/receive_buffer.hpp"

#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <exception>
#include <stdexcept>
#include <utility>

namespace graspfill::rt {
namespace {

// *bytes from `encode`; false where it throws (an inconsistent cloud or
// mesh: the caller's bug, not the bus's).
template <typename Encode>
bool TryEncode(Encode encode, std::vector<uint8_t>* bytes) {
  try {
    *bytes = encode();
  } catch (const std::exception&) {
    return false;
  }
  return true;
}

}  // namespace

class LcmPublisher::Impl {
 public:
  Impl(const std::string& url, const CloudPacing& pacing) : url_(url), lcm_(url) {
    if (!lcm_.good()) {
      throw std::runtime_error("cannot set up LCM on '" + (url.empty() ? std::string("default URL") : url) +
                               "'");
    }
    if (IsUdpMulticast(url)) {
      slice_message_bytes_ = pacing.slice_bytes + kSliceHeaderBytes;
      // The pacer's thread publishes too: LCM's udpm publish is thread safe.
      pacer_ = std::make_unique<CloudPacer>(
          pacing, [this](const std::string& channel, const std::vector<uint8_t>& slice) {
            return Publish(channel, slice);
          });
    }
  }
  // The pacer first: its thread sends what is queued while LCM still exists.
  ~Impl() { pacer_.reset(); }

  bool Publish(const std::string& channel, const std::vector<uint8_t>& bytes) {
    return lcm_.publish(channel, bytes.data(), static_cast<unsigned int>(bytes.size())) == 0;
  }

  const std::string& url() const { return url_; }
  lcm::LCM* lcm() { return &lcm_; }

  // Once per publisher: the first cloud too large for a default
  // subscriber's buffer.
  void CheckSize(size_t bytes) {
    if (warned_ || !on_warning_) return;
    const std::string warning = ReceiveBufferWarning(bytes, url_, settings_);
    if (warning.empty()) return;
    warned_ = true;
    on_warning_(warning);
  }
  std::function<void(const std::string&)> on_warning_;
  // Where clouds are paced (UDP multicast), else null.
  std::unique_ptr<CloudPacer> pacer_;
  // The largest message a paced cloud is cut into [bytes].
  size_t slice_message_bytes_{0};

 private:
  // object_cloud_chunk_t's header (lcmtypes/object_cloud_chunk_t.lcm).
  static constexpr size_t kSliceHeaderBytes = 48;
  const ReceiveBufferSettings settings_ = ReadReceiveBufferSettings();
  bool warned_ = false;
  std::string url_;
  lcm::LCM lcm_;
};

LcmPublisher::LcmPublisher(const std::string& url, const CloudPacing& pacing)
    : impl_(std::make_unique<Impl>(url, pacing)) {}

LcmPublisher::~LcmPublisher() = default;

bool LcmPublisher::PublishCloud(const std::string& channel, const ObjectCloud& cloud) {
  std::vector<uint8_t> bytes;
  if (!TryEncode([&] { return io::EncodeObjectCloud(cloud); }, &bytes)) return false;
  if (!impl_->pacer_) {
    impl_->CheckSize(bytes.size());
    return impl_->Publish(channel, bytes);
  }
  impl_->CheckSize(std::min(bytes.size(), impl_->slice_message_bytes_));
  impl_->pacer_->Submit(channel, std::move(bytes));
  return true;
}

bool LcmPublisher::FlushClouds(int timeout_ms) { return !impl_->pacer_ || impl_->pacer_->Flush(timeout_ms); }

int64_t LcmPublisher::paced_send_failures() const {
  return impl_->pacer_ ? impl_->pacer_->send_failures() : 0;
}

int64_t LcmPublisher::paced_clouds_dropped() const { return impl_->pacer_ ? impl_->pacer_->dropped() : 0; }

void LcmPublisher::set_on_warning(std::function<void(const std::string&)> on_warning) {
  impl_->on_warning_ = std::move(on_warning);
}

bool LcmPublisher::PublishCollisionMesh(const std::string& channel, const io::CollisionMeshMessage& mesh) {
  std::vector<uint8_t> bytes;
  if (!TryEncode([&] { return io::EncodeCollisionMesh(mesh); }, &bytes)) return false;
  // Whole on every provider, UDP multicast too (not through the pacer: its
  // slices are object_cloud_chunk_t's): ~90 kB at 5,000 triangles, one
  // message a replay, which a default receive buffer holds.
  impl_->CheckSize(bytes.size());
  return impl_->Publish(channel, bytes);
}

bool LcmPublisher::PublishStatus(const std::string& channel, const io::ModuleStatus& status) {
  return impl_->Publish(channel, io::EncodeModuleStatus(status));
}

bool LcmPublisher::PublishRaw(const std::string& channel, const std::vector<uint8_t>& bytes) {
  return impl_->Publish(channel, bytes);
}

const std::string& LcmPublisher::url() const { return impl_->url(); }

lcm::LCM* LcmPublisher::lcm_instance() { return impl_->lcm(); }

}  // namespace graspfill::rt
