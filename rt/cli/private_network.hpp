// SPDX-License-Identifier: BSD-3-Clause
// A private network namespace for benchmarks that need LCM's UDP multicast
// between processes: the calling thread (and every thread and process it
// starts afterwards) gets a namespace of its own with only the loopback
// interface, up, and a multicast route on it. Nothing sent there can reach
// the host's network.
#pragma once

#include <string>

namespace graspfill::cli {

/// Moves the calling thread into a new network namespace (unshare
/// CLONE_NEWNET: needs root or CAP_SYS_ADMIN) and sets up loopback
/// multicast. Call it before starting threads. Returns "" on success, else
/// why not (the caller then skips what needs it: never multicast on the
/// host's network).
std::string EnterPrivateNetwork();

}  // namespace graspfill::cli
