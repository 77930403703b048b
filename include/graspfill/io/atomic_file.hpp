// SPDX-License-Identifier: BSD-3-Clause
// Writing a file so that readers only ever see the old file or the whole new
// one: the bytes go to a temporary file in the target's folder, are flushed
// to the disk, and the temporary file is then renamed over the target. A
// failed write (full disk, I/O error) removes the temporary file and leaves
// the target as it was.
//
// Only regular files are written or replaced: a character or block device
// (/dev/null), a FIFO, a socket or a folder at the path is refused, whatever
// the IfExists (a FIFO is not streamed to). Without IfExists::kReplace the
// file is created only if nothing is at the path when the bytes are in
// place (renameat2 RENAME_NOREPLACE, or link(2) where the file system lacks
// it): of two writers racing to one new path exactly one wins, the other
// fails with EEXIST.
//
// File I/O at the API boundary: failures throw std::runtime_error naming the
// path and the system's reason (strerror). Reentrant; any thread.
#pragma once

#include <string>

namespace graspfill::io {

/// What a write does where something is already at its path.
enum class IfExists {
  /// A regular file is replaced (a command's --force); a symbolic link's
  /// target is written.
  kReplace,
  /// The write fails with EEXIST if anything is at the path (a file, a
  /// link even dangling), checked when the file is put in place.
  kFail,
};

/// kReplace where `overwrite` (a command's --force), else kFail.
constexpr IfExists ReplaceIf(bool overwrite) { return overwrite ? IfExists::kReplace : IfExists::kFail; }

/// Writes `bytes` to `path` atomically (see the file comment).
///
/// The temporary file is `DIR/.NAME.tmp-XXXXXX` beside `path`, created with
/// mode 0666 less the umask (as std::ofstream would). With kReplace, if
/// `path` is a symbolic link (even a dangling one) the file it points to is
/// written; commands refuse symlinks before that unless --force
/// (CheckOutputFile).
/// @param what the start of the error message, e.g. "cannot write PLY".
/// @param if_exists kFail: nothing at `path` may be replaced.
/// @throws std::runtime_error "<what> '<path>': <strerror or why>" on any
///   failure (EEXIST's "File exists" where kFail found something there, a
///   device, FIFO, socket or folder named as such); the target is then
///   untouched and no temporary file is left.
void WriteFileAtomically(const std::string& path, const std::string& bytes,
                         const std::string& what = "cannot write", IfExists if_exists = IfExists::kReplace);

/// A file written in place of `path` on Commit(), for writers that stream
/// (LCM logs): write to temp_path(), then Commit(). Destroyed or Abandon()ed
/// without Commit(), it removes the temporary file.
///
/// Not thread safe: one thread owns it.
class AtomicFile {
 public:
  /// Creates the (empty) temporary file beside `path`, after checking that
  /// `path` is missing or (with kReplace) a regular file.
  /// @throws std::runtime_error "<what> '<path>': <strerror or why>" if it
  ///   cannot, or something is at the path that may not be replaced.
  explicit AtomicFile(const std::string& path, const std::string& what = "cannot write",
                      IfExists if_exists = IfExists::kReplace);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// The file to write (with kReplace, the final path's symlink target if
  /// it is one).
  const std::string& path() const { return path_; }
  /// The temporary file the bytes go to until Commit().
  const std::string& temp_path() const { return temp_path_; }
  /// The temporary file's descriptor (open for writing, at offset 0).
  int fd() const { return fd_; }

  /// Flushes the temporary file to the disk and puts it in place at path():
  /// renamed over a regular file (kReplace), or only where nothing is there
  /// (kFail, else EEXIST). Whatever wrote to temp_path() through other
  /// descriptors must have flushed them first.
  /// @throws std::runtime_error (then the temporary file is removed).
  void Commit();
  /// Removes the temporary file; path() is untouched. Never throws.
  void Abandon() noexcept;

 private:
  [[noreturn]] void Fail(int error);
  // Throws if what is at path_ may not be replaced (see IfExists).
  void CheckTarget(bool at_commit) const;

  std::string what_;
  IfExists if_exists_;
  std::string path_;
  std::string temp_path_;
  int fd_{-1};
};

}  // namespace graspfill::io
