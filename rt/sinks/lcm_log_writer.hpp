// Writes LCM log files (lcm-logger's format, readable by lcm-logplayer,
// lcm-spy's log mode and LcmLogSource).
#pragma once

#include <cstdint>
#include <exception>
#include <memory>
#include <string>
#include <vector>

namespace lcm {
class LogFile;
}  // namespace lcm

namespace graspfill::io {
class AtomicFile;
}  // namespace graspfill::io

namespace graspfill::rt {

/// Appends events to a new LCM log file, written atomically: the events go
/// to a temporary file `DIR/.NAME.tmp-XXXXXX` beside the log, renamed into
/// place by Close() (or the destructor). A write error, or an exception
/// that unwinds past the writer, removes the temporary file and leaves any
/// existing file at the path as it was.
///
/// Not thread safe: one thread writes.
class LcmLogWriter {
 public:
  /// Creates the log.
  /// @param overwrite replace an existing file; if false an existing file
  ///   is an error (recordings are not clobbered by accident).
  /// @throws std::runtime_error naming the path if the file exists and
  ///   !overwrite, or it cannot be created.
  explicit LcmLogWriter(const std::string& path, bool overwrite = false);
  ~LcmLogWriter();
  LcmLogWriter(const LcmLogWriter&) = delete;
  LcmLogWriter& operator=(const LcmLogWriter&) = delete;

  /// Appends one event.
  /// @param channel LCM channel name (1..255 bytes).
  /// @param utime the event's log timestamp [us since epoch] (lcm-logger
  ///   stores the receive time; replay tools pace by it).
  /// @param bytes the encoded message.
  /// @throws std::runtime_error naming the path on a write error (disk
  ///   full) or a bad channel name.
  void Write(const std::string& channel, int64_t utime,
             const std::vector<uint8_t>& bytes);

  /// Pushes buffered events to the temporary file.
  /// @throws std::runtime_error naming the path on failure (the temporary
  ///   file is then removed and later calls throw).
  void Flush();

  /// Flushes, closes and renames the log into place; later writes throw.
  /// The destructor does this too, unless an exception is unwinding past
  /// the writer or a write failed (then the log is abandoned).
  /// @throws std::runtime_error naming the path (and strerror) on failure.
  void Close();

  /// Events written so far.
  int64_t events_written() const { return events_written_; }

 private:
  [[noreturn]] void Fail(const std::string& why);

  std::string path_;
  std::unique_ptr<io::AtomicFile> file_;
  std::unique_ptr<lcm::LogFile> log_;
  int64_t events_written_{0};
  /// std::uncaught_exceptions() at construction: more at destruction means
  /// the writer is being unwound and the log is incomplete.
  int uncaught_at_start_{std::uncaught_exceptions()};
};

}  // namespace graspfill::rt
