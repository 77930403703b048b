// SPDX-License-Identifier: BSD-3-Clause
// Writes LCM log files (lcm-logger's format, readable by lcm-logplayer,
// lcm-spy's log mode and LcmLogSource).
#pragma once

#include <cstdint>
#include <exception>
#include <memory>
#include <string>
#include <vector>

namespace graspfill::io {
class AtomicFile;
}  // namespace graspfill::io

namespace graspfill::rt {

/// Appends events to a new LCM log file. Each event goes to the file with
/// one write(2) as Write() is called (no buffering in the process: a crash
/// or a kill of the process loses no event Write() returned from).
///
/// Two ways to make the file (Mode):
///  - kAtomic (files made from start to end in one go, e.g. `graspfill
///    synth`'s recordings): the events go to a temporary file
///    `DIR/.NAME.tmp-XXXXXX` beside the log, renamed into place by Close()
///    (or the destructor). A write error, or an exception that unwinds past
///    the writer, removes the temporary file and leaves any existing file
///    at the path as it was.
///  - kInPlace (recordings of a live session, as lcm-logger writes them):
///    the log is at its final name from the start. What was written stays
///    whatever happens: after a crash, a kill or a power cut the file holds
///    every event written (up to the last Flush() for a power cut), then at
///    most a partial event, which readers skip (io::LcmLogReader:
///    kTruncated). A write error (a full disk) cuts the file back to its
///    last whole event and closes it: the log keeps what it had.
///
/// Not thread safe: one thread writes.
class LcmLogWriter {
 public:
  enum class Mode { kAtomic, kInPlace };
  struct Options {
    /// Replace an existing file; if false an existing file (or any link,
    /// even a dangling one) is an error: recordings are not clobbered by
    /// accident. Even with it, anything but a regular file (a directory, a
    /// FIFO, a device, a socket) is refused.
    bool overwrite{false};
    Mode mode{Mode::kAtomic};
  };

  /// Creates the log (kAtomic).
  /// @throws std::runtime_error naming the path if the file exists and
  ///   !overwrite, it is not a regular file, or it cannot be created.
  explicit LcmLogWriter(const std::string& path, bool overwrite = false);
  /// Creates the log; kInPlace creates it exclusively (O_EXCL) unless
  /// overwrite, and then truncates only a regular file.
  /// @throws std::runtime_error as above.
  LcmLogWriter(const std::string& path, const Options& options);
  ~LcmLogWriter();
  LcmLogWriter(const LcmLogWriter&) = delete;
  LcmLogWriter& operator=(const LcmLogWriter&) = delete;

  /// Appends one event.
  /// @param channel LCM channel name (1..255 bytes).
  /// @param utime the event's log timestamp [us since epoch] (lcm-logger
  ///   stores the receive time; replay tools pace by it).
  /// @param bytes the encoded message (at most io::kMaxLogEventDataBytes).
  /// @throws std::runtime_error naming the path: "cannot write log 'P':
  ///   <strerror>" on a write error (disk full; the log is then abandoned
  ///   (kAtomic) or cut back to its last whole event and closed (kInPlace),
  ///   and later calls throw), or a bad channel name or size (the log goes
  ///   on).
  void Write(const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes);

  /// Makes every event written so far durable (fdatasync): a power cut
  /// after it loses none of them.
  /// @throws std::runtime_error naming the path on failure (then as a
  ///   failed Write).
  void Flush();

  /// Flushes and closes the log (kAtomic: and renames it into place);
  /// later writes throw. The destructor does this too; unless, for
  /// kAtomic, an exception is unwinding past the writer or a write failed
  /// (then the temporary file is removed).
  /// @throws std::runtime_error naming the path (and strerror) on failure.
  void Close();

  /// Events written so far.
  int64_t events_written() const { return events_written_; }
  /// Bytes of the log so far (whole events).
  int64_t bytes_written() const { return bytes_written_; }

 private:
  [[noreturn]] void Fail(int error);
  void CheckOpen() const;

  std::string path_;
  Mode mode_;
  std::unique_ptr<io::AtomicFile> atomic_;  // kAtomic
  int fd_{-1};                              // the file written (either mode)
  bool failed_{false};
  int64_t events_written_{0};
  int64_t bytes_written_{0};
  /// std::uncaught_exceptions() at construction: more at destruction means
  /// the writer is being unwound and the log is incomplete.
  int uncaught_at_start_{std::uncaught_exceptions()};
};

}  // namespace graspfill::rt
