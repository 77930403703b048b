// Pieces of atomic_file.cpp that output_path.cpp shares (not API).
#pragma once

#include <string>

namespace graspfill::io::internal {

/// `path` with its last component's symbolic links followed (relative
/// targets against the link's folder), as open() would; `path` itself if it
/// is not a link.
std::string FollowSymlinks(const std::string& path);

/// Creates a new, empty temporary file `DIR/.NAME.tmp-XXXXXX` beside `path`
/// (mode 0666 less the umask, never through a link); its descriptor, or -1
/// with errno set.
int CreateTempFile(const std::string& path, std::string* temp_path);

}  // namespace graspfill::io::internal
