// Writes LCM log files (lcm-logger's format, readable by lcm-logplayer,
// lcm-spy's log mode and LcmLogSource).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace lcm {
class LogFile;
}  // namespace lcm

namespace graspfill::rt {

/// Appends events to a new LCM log file; the file is complete once the
/// writer is destroyed (or after Flush()).
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

  /// Pushes buffered events to the file.
  /// @throws std::runtime_error naming the path on failure.
  void Flush();

  /// Events written so far.
  int64_t events_written() const { return events_written_; }

 private:
  std::string path_;
  std::unique_ptr<lcm::LogFile> log_;
  int64_t events_written_{0};
};

}  // namespace graspfill::rt
