// Writing a file so that readers only ever see the old file or the whole new
// one: the bytes go to a temporary file in the target's folder, are flushed
// to the disk, and the temporary file is then renamed over the target. A
// failed write (full disk, I/O error) removes the temporary file and leaves
// the target as it was.
//
// File I/O at the API boundary: failures throw std::runtime_error naming the
// path and the system's reason (strerror). Reentrant; any thread.
#pragma once

#include <string>

namespace graspfill::io {

/// Writes `bytes` to `path` atomically (see the file comment).
///
/// The temporary file is `DIR/.NAME.tmp-XXXXXX` beside `path`, created with
/// mode 0666 less the umask (as std::ofstream would). If `path` is a
/// symbolic link (even a dangling one) the file it points to is written;
/// commands refuse symlinks before that unless --force (CheckOutputFile).
/// @param what the start of the error message, e.g. "cannot write PLY".
/// @throws std::runtime_error "<what> '<path>': <strerror>" on any failure;
///   the target is then untouched and no temporary file is left.
void WriteFileAtomically(const std::string& path, const std::string& bytes,
                         const std::string& what = "cannot write");

/// A file written in place of `path` on Commit(), for writers that stream
/// (LCM logs): write to temp_path(), then Commit(). Destroyed or Abandon()ed
/// without Commit(), it removes the temporary file.
///
/// Not thread safe: one thread owns it.
class AtomicFile {
 public:
  /// Creates the (empty) temporary file beside `path`.
  /// @throws std::runtime_error "<what> '<path>': <strerror>" if it cannot.
  explicit AtomicFile(const std::string& path, const std::string& what = "cannot write");
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// The file to write (the final path's symlink target, if it is one).
  const std::string& path() const { return path_; }
  /// The temporary file the bytes go to until Commit().
  const std::string& temp_path() const { return temp_path_; }
  /// The temporary file's descriptor (open for writing, at offset 0).
  int fd() const { return fd_; }

  /// Flushes the temporary file to the disk and renames it over path().
  /// Whatever wrote to temp_path() through other descriptors must have
  /// flushed them first.
  /// @throws std::runtime_error (then the temporary file is removed).
  void Commit();
  /// Removes the temporary file; path() is untouched. Never throws.
  void Abandon() noexcept;

 private:
  [[noreturn]] void Fail(int error);

  std::string what_;
  std::string path_;
  std::string temp_path_;
  int fd_{-1};
};

}  // namespace graspfill::io
