#include "sources/lcm_bus_subscriber.hpp"

#include <lcm/lcm-cpp.hpp>

#include <stdexcept>
#include <utility>

namespace graspfill::rt {

struct LcmBusSubscriber::Impl {
  explicit Impl(const std::string& url) : lcm(url) {}
  lcm::LCM lcm;
  Config config;
  StateCallback on_state;
  DepthCallback on_depth;
  GripperState state;  // decode targets, reused
  DepthFrame depth;
  std::string error;
};

LcmBusSubscriber::LcmBusSubscriber(const Config& config, StateCallback on_state,
                                   DepthCallback on_depth)
    : impl_(std::make_unique<Impl>(config.url)) {
  if (!impl_->lcm.good()) {
    throw std::runtime_error("cannot start LCM on '" +
                             (config.url.empty() ? std::string("LCM's default URL") : config.url) + "'");
  }
  impl_->config = config;
  impl_->on_state = std::move(on_state);
  impl_->on_depth = std::move(on_depth);
  // Handlers are called from LCM's C code: they count errors, never throw.
  impl_->lcm.subscribeFunction(
      config.channels.gripper_state,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, LcmBusSubscriber* self) {
        Impl& s = *self->impl_;
        if (!io::DecodeGripperState(rbuf->data, rbuf->data_size, s.config.T_C_B, &s.state, &s.error)) {
          ++self->decode_errors_;
          return;
        }
        ++self->states_received_;
        if (s.on_state) s.on_state(s.state);
      },
      this);
  if (impl_->on_depth) {
    impl_->lcm.subscribeFunction(
        config.channels.depth,
        +[](const lcm::ReceiveBuffer* rbuf, const std::string&, LcmBusSubscriber* self) {
          Impl& s = *self->impl_;
          if (!io::DecodeDepthImage(rbuf->data, rbuf->data_size, &s.depth, &s.error)) {
            ++self->decode_errors_;
            return;
          }
          ++self->depth_received_;
          s.on_depth(s.depth);
        },
        this);
  }
  thread_ = std::thread([this] {
    // Bounded waits so that the destructor is noticed promptly.
    while (!stop_) impl_->lcm.handleTimeout(50);
  });
}

LcmBusSubscriber::~LcmBusSubscriber() {
  stop_ = true;
  thread_.join();
}

}  // namespace graspfill::rt
