// SPDX-License-Identifier: BSD-3-Clause
#include "sinks/receive_buffer.hpp"

#include <cstdlib>
#include <fstream>

namespace graspfill::rt {
namespace {

std::optional<size_t> ReadSize(const char* path) {
  std::ifstream in(path);
  long long value = -1;
  if (!(in >> value) || value <= 0) return std::nullopt;
  return static_cast<size_t>(value);
}

}  // namespace

ReceiveBufferSettings ReadReceiveBufferSettings() {
  return {ReadSize("/proc/sys/net/core/rmem_default"), ReadSize("/proc/sys/net/core/rmem_max")};
}

bool IsUdpMulticast(const std::string& url) {
  std::string effective = url;
  if (effective.empty()) {
    const char* env = std::getenv("LCM_DEFAULT_URL");
    effective = env != nullptr ? env : "";
  }
  return effective.empty() || effective.rfind("udpm://", 0) == 0;
}

std::string ReceiveBufferWarning(size_t message_bytes, const std::string& url,
                                 const ReceiveBufferSettings& settings) {
  if (!IsUdpMulticast(url) || !settings.rmem_default) return "";
  const size_t buffer = *settings.rmem_default;
  if (static_cast<double>(message_bytes) <= kReceiveBufferShare * static_cast<double>(buffer)) return "";
  const size_t wanted = static_cast<size_t>(static_cast<double>(message_bytes) / kReceiveBufferShare) + 1;
  std::string text = "a published model of " + std::to_string(message_bytes / 1000) +
                     " kB may not reach subscribers that keep LCM's default receive buffer "
                     "(net.core.rmem_default = " +
                     std::to_string(buffer) +
                     " bytes): subscribers add ?recv_buf_size=" + std::to_string(wanted) +
                     " to their LCM URL";
  if (settings.rmem_max && *settings.rmem_max < wanted) {
    text += ", and the kernel must allow it (net.core.rmem_max = " + std::to_string(*settings.rmem_max) +
            "; sysctl -w net.core.rmem_max=" + std::to_string(wanted) + ")";
  }
  return text;
}

}  // namespace graspfill::rt
