// SPDX-License-Identifier: BSD-3-Clause
// Will a message reach a subscriber that kept LCM's defaults? LCM's UDP
// multicast sends a large message as a burst of 64 kB datagrams, and a
// subscriber's socket holds net.core.rmem_default bytes of them (Debian:
// 212,992) unless its URL asks for recv_buf_size, which the kernel caps at
// net.core.rmem_max. Measured in a private network namespace with LCM's
// default URL (docs/measurements/2026-12-06-cloud-delivery.md): up to
// 200 kB one message in 20 was lost now and then, from 300 kB nearly all.
// On UDP multicast a cloud's largest message is one slice (cloud_pacer.hpp),
// so this warns only where the buffer is smaller than a slice needs.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

namespace graspfill::rt {

/// The share of the receive buffer a message may take before the warning:
/// short of the sizes where most are lost.
constexpr double kReceiveBufferShare = 0.7;

/// The kernel's receive-buffer settings [bytes]: net.core.rmem_default and
/// net.core.rmem_max, none where /proc does not say.
struct ReceiveBufferSettings {
  std::optional<size_t> rmem_default;
  std::optional<size_t> rmem_max;
};
ReceiveBufferSettings ReadReceiveBufferSettings();

/// Whether `url` (as LcmPublisher takes it; "" is LCM_DEFAULT_URL or LCM's
/// default) is LCM's UDP multicast, the provider with this limit.
bool IsUdpMulticast(const std::string& url);

/// The warning for a message of `message_bytes` on `url`: empty where it
/// fits a default subscriber's buffer (or the URL is not UDP multicast, or
/// the kernel's settings are unknown); else one line naming the size, the
/// setting and what a subscriber can do.
std::string ReceiveBufferWarning(size_t message_bytes, const std::string& url,
                                 const ReceiveBufferSettings& settings);

}  // namespace graspfill::rt
