// SPDX-License-Identifier: BSD-3-Clause
// CheckOutputFile and PrepareOutputDir: what a command refuses before it
// starts its work.
#include "graspfill/io/output_path.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>

namespace graspfill::io {
namespace {

namespace fs = std::filesystem;

class OutputPathTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(GRASPFILL_BINARY_DIR) / "test_tmp" / "io_output_path" / info->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST_F(OutputPathTest, NewFileInAWritableFolderIsFineAndLeavesNothing) {
  EXPECT_EQ(ErrorOf([&] { CheckOutputFile(Path("new.ply"), false); }), "");
  EXPECT_TRUE(fs::is_empty(dir_));  // the probe file is gone
}

TEST_F(OutputPathTest, ExistingFileNeedsForce) {
  std::ofstream(Path("old.ply")) << "precious";
  const std::string error = ErrorOf([&] { CheckOutputFile(Path("old.ply"), false); });
  EXPECT_NE(error.find("'" + Path("old.ply") + "' exists; pass --force"), std::string::npos) << error;
  EXPECT_EQ(ErrorOf([&] { CheckOutputFile(Path("old.ply"), true); }), "");
}

TEST_F(OutputPathTest, SymlinksNeedForceEvenDangling) {
  fs::create_symlink(Path("nowhere.ply"), Path("dangling.ply"));
  const std::string error = ErrorOf([&] { CheckOutputFile(Path("dangling.ply"), false); });
  EXPECT_NE(error.find("is a symbolic link"), std::string::npos) << error;
  EXPECT_NE(error.find("--force"), std::string::npos) << error;
  EXPECT_EQ(ErrorOf([&] { CheckOutputFile(Path("dangling.ply"), true); }), "");
  // A link into a folder that does not exist cannot be written even so.
  fs::create_symlink(Path("gone/x.ply"), Path("broken.ply"));
  EXPECT_NE(ErrorOf([&] { CheckOutputFile(Path("broken.ply"), true); }).find("does not exist"),
            std::string::npos);
}

TEST_F(OutputPathTest, UnwritablePlacesAreRefusedWithTheReason) {
  EXPECT_NE(ErrorOf([&] {
              CheckOutputFile(Path("missing/x.ply"), true);
            }).find("folder '" + Path("missing") + "' does not exist"),
            std::string::npos);
  std::ofstream(Path("file")) << "x";
  EXPECT_NE(ErrorOf([&] { CheckOutputFile(Path("file/x.ply"), true); }).find("is not a folder"),
            std::string::npos);
  fs::create_directories(Path("folder"));
  EXPECT_NE(ErrorOf([&] { CheckOutputFile(Path("folder"), true); }).find("is a folder"), std::string::npos);
  // /proc takes no new files, not even from root (a read-only folder would
  // not stop root): the system's reason is in the message.
  const std::string proc = ErrorOf([&] { CheckOutputFile("/proc/graspfill.ply", false); });
  EXPECT_NE(proc.find("'/proc/graspfill.ply' cannot be written: folder '/proc': "), std::string::npos)
      << proc;
  EXPECT_EQ(ErrorOf([&] { CheckOutputFile("", true); }), "empty output path");
}

// A FIFO or a device is no output, --force or not: it used to pass with
// --force and be replaced by a regular file at the end of the command.
TEST_F(OutputPathTest, FifosAndDevicesAreRefusedEvenWithForce) {
  ASSERT_EQ(::mkfifo(Path("fifo").c_str(), 0666), 0) << std::strerror(errno);
  for (const bool force : {false, true}) {
    const std::string error = ErrorOf([&] { CheckOutputFile(Path("fifo"), force); });
    EXPECT_NE(error.find("'" + Path("fifo") + "' is a FIFO (named pipe), not a regular file"),
              std::string::npos)
        << error;
    // /dev/null itself is only looked at here, never written.
    EXPECT_NE(ErrorOf([&] { CheckOutputFile("/dev/null", force); }).find("is a character device"),
              std::string::npos);
  }
  // Through a link (--force follows links).
  fs::create_symlink(Path("fifo"), Path("to_fifo.ply"));
  fs::create_symlink("/dev/null", Path("to_null.ply"));
  EXPECT_NE(ErrorOf([&] { CheckOutputFile(Path("to_fifo.ply"), true); }).find("which is a FIFO"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              CheckOutputFile(Path("to_null.ply"), true);
            }).find("points to '/dev/null', which is a character device"),
            std::string::npos);
}

TEST_F(OutputPathTest, PrepareOutputDirCreatesFoldersOrSaysWhyNot) {
  EXPECT_EQ(ErrorOf([&] { PrepareOutputDir(Path("a/b/c")); }), "");
  EXPECT_TRUE(fs::is_directory(Path("a/b/c")));
  EXPECT_TRUE(fs::is_empty(Path("a/b/c")));
  std::ofstream(Path("file")) << "x";
  const std::string error = ErrorOf([&] { PrepareOutputDir(Path("file/sub")); });
  EXPECT_NE(error.find("cannot create '" + Path("file/sub") + "'"), std::string::npos) << error;
}

}  // namespace
}  // namespace graspfill::io
