// SPDX-License-Identifier: BSD-3-Clause
// A bounded reader of LCM log files (lcm-logger's format), used instead of
// liblcm's: liblcm allocates and reads whatever an event header declares
// (a 48-byte file declaring 2 GB of data crashes it). Here every length is
// checked against the bytes left in the file before anything is allocated,
// so a corrupt or hostile log ends reading with a reason, never a crash.
//
// Format (big-endian), one event after the other:
//   uint32 sync 0xEDA1DA01, int64 event number, int64 timestamp [us],
//   int32 channel length, int32 data length, channel bytes, data bytes.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace graspfill::io {

/// Limits of one event (documented in docs/input-limits-and-fuzzing.md).
/// LCM itself refuses channels over 63 bytes; 1024 leaves room for tools
/// that do not.
constexpr int32_t kMaxLogChannelBytes = 1024;
/// Largest event payload read (a 4096 x 4096 raw16 depth image is 32 MiB).
constexpr int64_t kMaxLogEventDataBytes = int64_t{256} << 20;
/// Bytes of an event header: sync, event number, timestamp, two lengths.
constexpr int64_t kLogEventHeaderBytes = 4 + 8 + 8 + 4 + 4;
/// The sync word that starts every event.
constexpr uint32_t kLogEventSync = 0xEDA1DA01u;

/// One event of a log. Buffers are reused across LcmLogReader::Next calls.
struct LogEvent {
  int64_t event_number{0};
  int64_t timestamp_us{0};
  std::string channel;
  std::vector<uint8_t> data;
};

/// Why LcmLogReader::Next stopped producing events.
enum class LogReadResult {
  kEvent,      ///< *event holds the next event
  kEnd,        ///< clean end: nothing left after the last event
  kTruncated,  ///< the last event is cut short (a log copied while written, or
               ///< a recording cut by a crash, a kill, a power cut, a full disk):
               ///< the events before it are whole
  kCorrupt,    ///< the bytes at the current offset are not an event
};

/// Reads events in file order. Not thread safe; one reader per thread.
class LcmLogReader {
 public:
  /// Opens `path`.
  /// @throws std::runtime_error "cannot open log '<path>': <reason>" if it
  ///   is missing, a directory, not a regular file (a FIFO, a device: they
  ///   could block forever or have no size to check lengths against) or
  ///   unreadable; "'<path>' is not an LCM log (...)" if it does not start
  ///   with the sync word. An empty file is a log with no events.
  explicit LcmLogReader(const std::string& path);
  /// Reads from an already open stream of `size` bytes (e.g. fmemopen: the
  /// fuzz target); `name` names it in errors. Does not take ownership.
  LcmLogReader(std::FILE* file, int64_t size, std::string name);
  ~LcmLogReader();
  LcmLogReader(const LcmLogReader&) = delete;
  LcmLogReader& operator=(const LcmLogReader&) = delete;

  /// Reads the next event into *event. After anything but kEvent, every
  /// later call returns the same result again.
  LogReadResult Next(LogEvent* event);

  /// Why reading stopped early (kTruncated / kCorrupt), naming the file,
  /// the offset and the field; "" otherwise.
  const std::string& error() const { return error_; }
  /// Offset of the next event [bytes].
  int64_t offset() const { return offset_; }
  int64_t file_size() const { return size_; }

 private:
  LogReadResult Stop(LogReadResult result, const std::string& why);

  std::FILE* file_{nullptr};
  bool owns_file_{false};
  int64_t size_{0};
  int64_t offset_{0};
  std::string name_;
  std::string error_;
  bool stopped_{false};
  LogReadResult stop_result_{LogReadResult::kEnd};
};

}  // namespace graspfill::io
