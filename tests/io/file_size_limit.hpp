// SPDX-License-Identifier: BSD-3-Clause
// A full disk for a test, even as root: RLIMIT_FSIZE makes writes beyond the
// limit fail with EFBIG ("File too large") for every user (root's
// CAP_DAC_OVERRIDE defeats a read-only folder, not this), and SIGXFSZ,
// which would kill the process, is ignored meanwhile. Restored on
// destruction. Only what this process writes is limited.
#pragma once

#include <sys/resource.h>

#include <csignal>

namespace graspfill::testing {

class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    getrlimit(RLIMIT_FSIZE, &old_);
    rlimit limit = old_;
    limit.rlim_cur = bytes;
    ok_ = setrlimit(RLIMIT_FSIZE, &limit) == 0;
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

  /// Whether the limit is in force.
  bool ok() const { return ok_; }

 private:
  rlimit old_{};
  void (*old_handler_)(int){nullptr};
  bool ok_{false};
};

}  // namespace graspfill::testing
