// SPDX-License-Identifier: BSD-3-Clause
// WriteFileAtomically and AtomicFile: the target is replaced only by a
// complete file; a failed write (a full disk, simulated by RLIMIT_FSIZE,
// see file_size_limit.hpp) leaves it as it was and no temporary file
// behind; errors name the path and the system's reason. Only regular files
// are written (a device, FIFO or socket never replaced), and without
// IfExists::kReplace of writers racing to one new path exactly one wins.
#include "graspfill/io/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "file_size_limit.hpp"

namespace graspfill::io {
namespace {

namespace fs = std::filesystem;

class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(GRASPFILL_BINARY_DIR) / "test_tmp" / "io_atomic_file" / info->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  // Every name in the folder (temporary files start with a dot).
  std::vector<std::string> Names() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }

  fs::path dir_;
};

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST_F(AtomicFileTest, WritesAndReplacesLeavingOnlyTheFile) {
  WriteFileAtomically(Path("a.txt"), "first");
  EXPECT_EQ(ReadBytes(Path("a.txt")), "first");
  WriteFileAtomically(Path("a.txt"), "second, longer");
  EXPECT_EQ(ReadBytes(Path("a.txt")), "second, longer");
  WriteFileAtomically(Path("empty.txt"), "");
  EXPECT_TRUE(fs::is_regular_file(Path("empty.txt")));
  EXPECT_EQ(fs::file_size(Path("empty.txt")), 0u);
  EXPECT_EQ(Names(), (std::vector<std::string>{"a.txt", "empty.txt"}));
}

TEST_F(AtomicFileTest, ModeIsTheUmasksNotATemporaryFilesPrivateOne) {
  const mode_t mask = ::umask(022);
  WriteFileAtomically(Path("m.txt"), "x");
  ::umask(mask);
  struct stat st {};
  ASSERT_EQ(::stat(Path("m.txt").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0644u);  // mkstemp would give 0600
}

TEST_F(AtomicFileTest, FullDiskKeepsTheGoodFileAndRemovesTheTemporaryOne) {
  WriteFileAtomically(Path("good.ply"), "the good file");
  const std::string big(64 * 1024, 'x');
  std::string error;
  {
    testing::FileSizeLimit full(4096);
    ASSERT_TRUE(full.ok());
    error = ErrorOf([&] { WriteFileAtomically(Path("good.ply"), big, "cannot write PLY"); });
  }
  EXPECT_NE(error.find("cannot write PLY '" + Path("good.ply") + "'"), std::string::npos) << error;
  EXPECT_NE(error.find(std::strerror(EFBIG)), std::string::npos) << error;
  EXPECT_EQ(ReadBytes(Path("good.ply")), "the good file");
  EXPECT_EQ(Names(), std::vector<std::string>{"good.ply"});
}

TEST_F(AtomicFileTest, ErrorsNameThePathAndTheReason) {
  const std::string missing = Path("no/such/dir/x.txt");
  const std::string error = ErrorOf([&] { WriteFileAtomically(missing, "x"); });
  EXPECT_NE(error.find("'" + missing + "'"), std::string::npos) << error;
  EXPECT_NE(error.find(std::strerror(ENOENT)), std::string::npos) << error;
  // A folder where the file should be: the rename fails, nothing is left.
  fs::create_directories(Path("sub/dir"));
  const std::string over_dir = ErrorOf([&] { WriteFileAtomically(Path("sub/dir"), "x"); });
  EXPECT_NE(over_dir.find(Path("sub/dir")), std::string::npos) << over_dir;
  EXPECT_NE(over_dir.find(std::strerror(EISDIR)), std::string::npos) << over_dir;
  EXPECT_EQ(std::distance(fs::directory_iterator(Path("sub")), fs::directory_iterator()), 1);
}

TEST_F(AtomicFileTest, ASymlinkIsWrittenThroughAndStaysALink) {
  // CheckOutputFile refuses links without --force; with it, the file the
  // link names is replaced, atomically, in its own folder.
  fs::create_directories(Path("real"));
  fs::create_symlink("real/target.txt", Path("link.txt"));  // dangling
  WriteFileAtomically(Path("link.txt"), "through");
  EXPECT_TRUE(fs::is_symlink(Path("link.txt")));
  EXPECT_EQ(ReadBytes(Path("real/target.txt")), "through");
  WriteFileAtomically(Path("link.txt"), "again");
  EXPECT_EQ(ReadBytes(Path("real/target.txt")), "again");
}

TEST_F(AtomicFileTest, UncommittedFileLeavesTheTargetAlone) {
  WriteFileAtomically(Path("log"), "old");
  {
    AtomicFile file(Path("log"));
    EXPECT_EQ(fs::path(file.temp_path()).parent_path(), dir_);
    EXPECT_EQ(fs::path(file.temp_path()).filename().string().rfind(".log.tmp-", 0), 0u) << file.temp_path();
    std::ofstream(file.temp_path()) << "half written";
    EXPECT_EQ(ReadBytes(Path("log")), "old");
  }
  EXPECT_EQ(ReadBytes(Path("log")), "old");
  EXPECT_EQ(Names(), std::vector<std::string>{"log"});
  {
    AtomicFile file(Path("log"));
    std::ofstream(file.temp_path()) << "whole";
    file.Commit();
  }
  EXPECT_EQ(ReadBytes(Path("log")), "whole");
  EXPECT_EQ(Names(), std::vector<std::string>{"log"});
}

// The file type at `path` (not following a link), 0 if nothing is there.
mode_t TypeAt(const std::string& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0 ? (st.st_mode & S_IFMT) : 0;
}

TEST_F(AtomicFileTest, WithoutReplaceAnythingThereIsAnErrorAndKeptAsItWas) {
  WriteFileAtomically(Path("old.ply"), "precious");
  const std::string error =
      ErrorOf([&] { WriteFileAtomically(Path("old.ply"), "new", "cannot write PLY", IfExists::kFail); });
  EXPECT_NE(error.find("cannot write PLY '" + Path("old.ply") + "': " + std::strerror(EEXIST)),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("--force"), std::string::npos) << error;
  EXPECT_EQ(ReadBytes(Path("old.ply")), "precious");
  // A link, even a dangling one, is something there: not written through.
  fs::create_symlink("nowhere.ply", Path("link.ply"));
  EXPECT_NE(ErrorOf([&] {
              WriteFileAtomically(Path("link.ply"), "x", "cannot write", IfExists::kFail);
            }).find(std::strerror(EEXIST)),
            std::string::npos);
  EXPECT_FALSE(fs::exists(Path("nowhere.ply")));
  // Where nothing is, the file is made.
  WriteFileAtomically(Path("new.ply"), "fresh", "cannot write", IfExists::kFail);
  EXPECT_EQ(ReadBytes(Path("new.ply")), "fresh");
  EXPECT_EQ(Names(), (std::vector<std::string>{"link.ply", "new.ply", "old.ply"}));
}

// Two writers that both found the path free when they began: the second
// to finish fails with EEXIST instead of replacing the first one's file
// (both used to succeed, and one file was lost).
TEST_F(AtomicFileTest, OfTwoWritersToOneNewPathTheSecondToFinishFails) {
  AtomicFile first(Path("cloud.ply"), "cannot write PLY", IfExists::kFail);
  AtomicFile second(Path("cloud.ply"), "cannot write PLY", IfExists::kFail);
  std::ofstream(first.temp_path()) << "first";
  std::ofstream(second.temp_path()) << "second";
  first.Commit();
  const std::string error = ErrorOf([&] { second.Commit(); });
  EXPECT_NE(error.find("cannot write PLY '" + Path("cloud.ply") + "': " + std::strerror(EEXIST)),
            std::string::npos)
      << error;
  EXPECT_EQ(ReadBytes(Path("cloud.ply")), "first");
  EXPECT_EQ(Names(), std::vector<std::string>{"cloud.ply"});  // no temporary file left
}

TEST_F(AtomicFileTest, OfManyThreadsRacingToOneNewPathExactlyOneWins) {
  constexpr int kWriters = 8;
  for (int round = 0; round < 20; ++round) {
    const std::string path = Path("race" + std::to_string(round) + ".ply");
    std::atomic<int> ready{0};
    std::vector<std::string> errors(kWriters);
    std::vector<std::thread> writers;
    for (int w = 0; w < kWriters; ++w) {
      writers.emplace_back([&, w] {
        ++ready;
        while (ready.load() < kWriters) std::this_thread::yield();  // all start together
        errors[static_cast<size_t>(w)] = ErrorOf([&] {
          WriteFileAtomically(path, "writer " + std::to_string(w) + std::string(4096, 'x'),
                              "cannot write PLY", IfExists::kFail);
        });
      });
    }
    for (std::thread& t : writers) t.join();
    int winners = 0;
    std::string winner_bytes;
    for (int w = 0; w < kWriters; ++w) {
      const std::string& e = errors[static_cast<size_t>(w)];
      if (e.empty()) {
        ++winners;
        winner_bytes = "writer " + std::to_string(w) + std::string(4096, 'x');
      } else {
        EXPECT_NE(e.find(std::strerror(EEXIST)), std::string::npos) << e;
      }
    }
    EXPECT_EQ(winners, 1) << "round " << round;
    EXPECT_EQ(ReadBytes(path), winner_bytes) << "round " << round;
  }
  EXPECT_EQ(Names().size(), 20u);  // the 20 files, no temporary ones
}

// A FIFO, a device or a socket where the file should go is refused, even
// with kReplace (a command's --force), and stays what it was: it used to
// be replaced by a regular file.
TEST_F(AtomicFileTest, DevicesFifosAndSocketsAreNeverReplaced) {
  std::vector<std::pair<std::string, std::string>> specials;  // path, kind in the message
  ASSERT_EQ(::mkfifo(Path("fifo").c_str(), 0666), 0) << std::strerror(errno);
  specials.emplace_back(Path("fifo"), "is a FIFO (named pipe)");
  // /dev/null's twin, where this process may make one (root, not in every
  // container).
  if (::mknod(Path("null").c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0) {
    specials.emplace_back(Path("null"), "is a character device");
  }
  const int sock = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(sock, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  const std::string socket_path = Path("sock");
  if (socket_path.size() < sizeof(address.sun_path)) {
    std::strncpy(address.sun_path, socket_path.c_str(), sizeof(address.sun_path) - 1);
    if (::bind(sock, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0) {
      specials.emplace_back(socket_path, "is a socket");
    }
  }
  ::close(sock);
  for (const auto& [path, kind] : specials) {
    const mode_t type = TypeAt(path);
    for (const IfExists if_exists : {IfExists::kReplace, IfExists::kFail}) {
      const std::string error =
          ErrorOf([&] { WriteFileAtomically(path, "x", "cannot write PLY", if_exists); });
      EXPECT_NE(error.find("cannot write PLY '" + path + "': " + kind), std::string::npos) << error;
      EXPECT_EQ(TypeAt(path), type) << path;
    }
    // Through a link too (a link's target is written with kReplace).
    const std::string link = path + ".link";
    fs::create_symlink(path, link);
    EXPECT_NE(ErrorOf([&] { WriteFileAtomically(link, "x", "cannot write", IfExists::kReplace); }).find(kind),
              std::string::npos);
    EXPECT_EQ(TypeAt(path), type) << path;
  }
  // Nothing but the specials and their links: no temporary file.
  EXPECT_EQ(Names().size(), 2 * specials.size());
}

}  // namespace
}  // namespace graspfill::io
