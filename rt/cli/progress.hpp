// SPDX-License-Identifier: BSD-3-Clause
// A progress line on stderr for the long commands (replay, synth, bench):
// work done / total, rate and time left, one line rewritten with '\r'. Drawn
// only when stderr is a terminal and --quiet was not given, so that pipes,
// logs and tests never see it.
#pragma once

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>

namespace graspfill::cli {

/// --quiet (any command; main takes it off the arguments): no progress line.
inline bool& ProgressQuiet() {
  static bool quiet = false;
  return quiet;
}

/// Whether a progress line is drawn: stderr a terminal, no --quiet.
inline bool ProgressWanted() { return !ProgressQuiet() && isatty(STDERR_FILENO) == 1; }

/// The line's text: "replay: 120/900 frames (13%), 35.2 frames/s, 22 s left";
/// without a total (0) "replay: 120 frames, 35.2 frames/s"; the rate and
/// the time left only once some time has passed; `done` capped at `total`.
inline std::string FormatProgress(const std::string& what, const std::string& unit, int64_t done,
                                  int64_t total, double elapsed_s) {
  char buf[256];
  if (total > 0 && done > total) done = total;
  std::string line = what + ": " + std::to_string(done);
  if (total > 0) {
    std::snprintf(buf, sizeof(buf), "/%lld %s (%d%%)", static_cast<long long>(total), unit.c_str(),
                  static_cast<int>(100 * done / total));
  } else {
    std::snprintf(buf, sizeof(buf), " %s", unit.c_str());
  }
  line += buf;
  if (elapsed_s <= 0.0 || done <= 0) return line;
  const double rate = done / elapsed_s;
  std::snprintf(buf, sizeof(buf), ", %.1f %s/s", rate, unit.c_str());
  line += buf;
  if (total > done) {
    const auto left_s = static_cast<long long>(std::ceil((total - done) / rate));
    if (left_s >= 60) {
      std::snprintf(buf, sizeof(buf), ", %lld min %02lld s left", left_s / 60, left_s % 60);
    } else {
      std::snprintf(buf, sizeof(buf), ", %lld s left", left_s);
    }
    line += buf;
  }
  return line;
}

/// The progress of one piece of work. Not thread safe: the thread doing
/// the work owns it.
class ProgressLine {
 public:
  /// `what` names the work ("replay"), `unit` what is counted ("frames");
  /// `total` 0 when unknown.
  ProgressLine(std::string what, std::string unit, int64_t total)
      : what_(std::move(what)),
        unit_(std::move(unit)),
        total_(total),
        enabled_(ProgressWanted()),
        start_(Clock::now()) {}
  ~ProgressLine() { Clear(); }
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  bool enabled() const { return enabled_; }

  /// `done` units finished; redrawn at most every 0.2 s (and at the end).
  void Update(int64_t done) {
    if (!enabled_) return;
    const Clock::time_point now = Clock::now();
    if (shown_ && now - last_draw_ < std::chrono::milliseconds(200) && done != total_) return;
    last_draw_ = now;
    shown_ = true;
    const double elapsed_s = std::chrono::duration<double>(now - start_).count();
    // \033[K erases what a longer previous line left.
    std::fprintf(stderr, "\r%s\033[K", FormatProgress(what_, unit_, done, total_, elapsed_s).c_str());
    std::fflush(stderr);
  }

  /// Erases the line (before other output to the terminal, and at the end).
  void Clear() {
    if (!shown_) return;
    std::fputs("\r\033[K", stderr);
    std::fflush(stderr);
    shown_ = false;
  }

 private:
  using Clock = std::chrono::steady_clock;
  std::string what_;
  std::string unit_;
  int64_t total_;
  bool enabled_;
  bool shown_{false};
  Clock::time_point start_;
  Clock::time_point last_draw_;
};

}  // namespace graspfill::cli
