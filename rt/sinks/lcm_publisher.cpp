// SPDX-License-Identifier: BSD-3-Clause
#include "sinks/lcm_publisher.hpp"

#include "sinks/receive_buffer.hpp"

#include <lcm/lcm-cpp.hpp>

#include <exception>
#include <stdexcept>
#include <utility>

namespace graspfill::rt {

class LcmPublisher::Impl {
 public:
  explicit Impl(const std::string& url) : url_(url), lcm_(url) {
    if (!lcm_.good()) {
      throw std::runtime_error(
          "cannot set up LCM on '" +
          (url.empty() ? std::string("default URL") : url) + "'");
    }
  }

  bool Publish(const std::string& channel, const std::vector<uint8_t>& bytes) {
    return lcm_.publish(channel, bytes.data(),
                        static_cast<unsigned int>(bytes.size())) == 0;
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

 private:
  const ReceiveBufferSettings settings_ = ReadReceiveBufferSettings();
  bool warned_ = false;
  std::string url_;
  lcm::LCM lcm_;
};

LcmPublisher::LcmPublisher(const std::string& url)
    : impl_(std::make_unique<Impl>(url)) {}

LcmPublisher::~LcmPublisher() = default;

bool LcmPublisher::PublishCloud(const std::string& channel,
                                const ObjectCloud& cloud) {
  std::vector<uint8_t> bytes;
  try {
    bytes = io::EncodeObjectCloud(cloud);
  } catch (const std::exception&) {
    return false;  // an inconsistent cloud: the caller's bug, not the bus's
  }
  impl_->CheckSize(bytes.size());
  return impl_->Publish(channel, bytes);
}

void LcmPublisher::set_on_warning(std::function<void(const std::string&)> on_warning) {
  impl_->on_warning_ = std::move(on_warning);
}

bool LcmPublisher::PublishStatus(const std::string& channel,
                                 const io::ModuleStatus& status) {
  return impl_->Publish(channel, io::EncodeModuleStatus(status));
}

bool LcmPublisher::PublishRaw(const std::string& channel,
                              const std::vector<uint8_t>& bytes) {
  return impl_->Publish(channel, bytes);
}

const std::string& LcmPublisher::url() const { return impl_->url(); }

lcm::LCM* LcmPublisher::lcm_instance() { return impl_->lcm(); }

}  // namespace graspfill::rt
