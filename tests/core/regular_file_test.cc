// SPDX-License-Identifier: BSD-3-Clause
// Reading files by name only when they are regular files (issue 36): a
// FIFO, a device or a folder is refused with one wording, without being
// opened for a blocking read; a file over the size limit is refused before
// it is read.
#include "graspfill/core/regular_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <stdexcept>
#include <string>

namespace graspfill {
namespace {

namespace fs = std::filesystem;

class RegularFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) /
           ("regular_file_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string ReadError(const std::string& path, int64_t max_bytes = 1 << 20) {
    try {
      ReadRegularFile(path, max_bytes, "cannot read thing");
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(RegularFileTest, ReadsARegularFileWhole) {
  const std::string path = (dir_ / "a.txt").string();
  std::ofstream(path, std::ios::binary) << std::string("ab\0cd", 5);
  EXPECT_EQ(NotARegularFile(path), "");
  EXPECT_EQ(ReadRegularFile(path, 5, "x"), std::string("ab\0cd", 5));
  EXPECT_EQ(ReadError(path, 4), "cannot read thing '" + path + "': larger than 4 bytes (5 bytes)");
  const std::string empty = (dir_ / "empty").string();
  std::ofstream{empty};
  EXPECT_EQ(ReadRegularFile(empty, 0, "x"), "");
}

TEST_F(RegularFileTest, RefusesWhatIsNotARegularFileInOneWording) {
  const std::string missing = (dir_ / "missing").string();
  EXPECT_EQ(NotARegularFile(missing), "no such file");
  EXPECT_EQ(ReadError(missing), "cannot read thing '" + missing + "': no such file");
  EXPECT_EQ(NotARegularFile(dir_.string()), "is a directory");
  for (const std::string device : {"/dev/zero", "/dev/null"}) {
    EXPECT_EQ(ReadError(device).rfind("cannot read thing '" + device +
                                          "': not a regular file (a "
                                          "FIFO, socket or device: it could block or never end)",
                                      0),
              0u)
        << ReadError(device);
  }
  // A FIFO with no writer: refused at once, not a read that waits for one
  // (the future's wait keeps a regression from hanging the test).
  const std::string fifo = (dir_ / "fifo").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto error = std::async(std::launch::async, [&] { return ReadError(fifo); });
  ASSERT_EQ(error.wait_for(std::chrono::seconds(10)), std::future_status::ready) << "reading a FIFO blocked";
  EXPECT_NE(error.get().find("'" + fifo + "': not a regular file"), std::string::npos);
  // Through a symbolic link: what it points at.
  const std::string link = (dir_ / "link").string();
  fs::create_symlink(fifo, link);
  EXPECT_NE(NotARegularFile(link).find("not a regular file"), std::string::npos);
}

}  // namespace
}  // namespace graspfill
