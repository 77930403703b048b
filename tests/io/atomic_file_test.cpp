// WriteFileAtomically and AtomicFile: the target is replaced only by a
// complete file; a failed write (a full disk, simulated by RLIMIT_FSIZE,
// see file_size_limit.hpp) leaves it as it was and no temporary file
// behind; errors name the path and the system's reason.
#include "graspfill/io/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstring>
#include <functional>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
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
    EXPECT_EQ(fs::path(file.temp_path()).filename().string().rfind(".log.tmp-", 0), 0u)
        << file.temp_path();
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

}  // namespace
}  // namespace graspfill::io
