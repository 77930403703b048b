// SPDX-License-Identifier: BSD-3-Clause
// The bounded LCM log reader: lengths checked against the file (issue 12:
// a 48-byte log declaring datalen 0x7fffffff crashed liblcm's reader), the
// truncation and corruption cases, FIFOs refused instead of blocking.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "graspfill/io/lcm_log_reader.hpp"

namespace graspfill::io {
namespace {

namespace fs = std::filesystem;

void PutBigEndian(std::vector<uint8_t>* out, uint64_t v, int n) {
  for (int i = n - 1; i >= 0; --i) out->push_back(static_cast<uint8_t>(v >> (8 * i)));
}

// One event header with the given lengths, then `body` bytes.
std::vector<uint8_t> Event(int64_t number, int64_t utime, int32_t channel_len, int32_t data_len,
                           const std::string& body) {
  std::vector<uint8_t> e;
  PutBigEndian(&e, 0xEDA1DA01u, 4);
  PutBigEndian(&e, static_cast<uint64_t>(number), 8);
  PutBigEndian(&e, static_cast<uint64_t>(utime), 8);
  PutBigEndian(&e, static_cast<uint32_t>(channel_len), 4);
  PutBigEndian(&e, static_cast<uint32_t>(data_len), 4);
  e.insert(e.end(), body.begin(), body.end());
  return e;
}

class LcmLogReaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(GRASPFILL_BINARY_DIR) / "test_tmp" / "io_lcm_log_reader" /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  std::string Write(const std::string& name, const std::vector<uint8_t>& bytes) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    return path;
  }
  fs::path dir_;
};

TEST_F(LcmLogReaderTest, ReadsEventsInOrder) {
  std::vector<uint8_t> bytes = Event(0, 10, 2, 3, "CHabc");
  const std::vector<uint8_t> second = Event(1, 20, 1, 0, "X");
  bytes.insert(bytes.end(), second.begin(), second.end());
  LcmLogReader reader(Write("two.lcmlog", bytes));
  LogEvent e;
  ASSERT_EQ(reader.Next(&e), LogReadResult::kEvent);
  EXPECT_EQ(e.channel, "CH");
  EXPECT_EQ(std::string(e.data.begin(), e.data.end()), "abc");
  EXPECT_EQ(e.timestamp_us, 10);
  ASSERT_EQ(reader.Next(&e), LogReadResult::kEvent);
  EXPECT_EQ(e.channel, "X");
  EXPECT_TRUE(e.data.empty());
  EXPECT_EQ(e.event_number, 1);
  EXPECT_EQ(reader.Next(&e), LogReadResult::kEnd);
  EXPECT_EQ(reader.Next(&e), LogReadResult::kEnd);
  EXPECT_EQ(reader.error(), "");
}

// The 48-byte log: one header declaring 0x7fffffff bytes of data.
TEST_F(LcmLogReaderTest, HugeDeclaredDataLengthIsTruncationNotACrash) {
  std::vector<uint8_t> bytes = Event(0, 0, 8, 0x7fffffff, "GRASPFIL");
  bytes.resize(48, 0);
  ASSERT_EQ(bytes.size(), 48u);
  const std::string path = Write("huge.lcmlog", bytes);
  LcmLogReader reader(path);
  LogEvent e;
  EXPECT_EQ(reader.Next(&e), LogReadResult::kCorrupt);  // over the per-event limit
  EXPECT_NE(reader.error().find(path), std::string::npos) << reader.error();
  EXPECT_NE(reader.error().find("data length 2147483647"), std::string::npos) << reader.error();
  // Near 2^31 but under the limit would still be more than the file holds.
  LcmLogReader near(Write("near.lcmlog", Event(0, 0, 1, 0x0fffffff, "C1234567")));
  EXPECT_EQ(near.Next(&e), LogReadResult::kTruncated);
  EXPECT_NE(near.error().find("left in the file"), std::string::npos) << near.error();
  // Negative lengths (the high bit set).
  LcmLogReader negative(Write("neg.lcmlog", Event(0, 0, -1, 4, "abcd")));
  EXPECT_EQ(negative.Next(&e), LogReadResult::kCorrupt);
  LcmLogReader negative_data(Write("negdata.lcmlog", Event(0, 0, 1, int32_t(0x80000000u), "abcd")));
  EXPECT_EQ(negative_data.Next(&e), LogReadResult::kCorrupt);
}

TEST_F(LcmLogReaderTest, CutsAndGarbageAfterAnEventStopReading) {
  const std::vector<uint8_t> good = Event(0, 1, 1, 2, "Cab");
  for (size_t extra : {size_t{1}, size_t{3}, size_t{27}, size_t{29}}) {
    std::vector<uint8_t> bytes = good;
    const std::vector<uint8_t> next = Event(1, 2, 1, 2, "Ccd");
    bytes.insert(bytes.end(), next.begin(), next.begin() + static_cast<long>(extra));
    LcmLogReader reader(Write("cut" + std::to_string(extra) + ".lcmlog", bytes));
    LogEvent e;
    EXPECT_EQ(reader.Next(&e), LogReadResult::kEvent);
    EXPECT_EQ(reader.Next(&e), LogReadResult::kTruncated) << extra;
  }
  std::vector<uint8_t> garbage = good;
  garbage.insert(garbage.end(), 40, 0x55);
  LcmLogReader reader(Write("garbage.lcmlog", garbage));
  LogEvent e;
  EXPECT_EQ(reader.Next(&e), LogReadResult::kEvent);
  EXPECT_EQ(reader.Next(&e), LogReadResult::kCorrupt);
  EXPECT_NE(reader.error().find("byte 31"), std::string::npos) << reader.error();
}

// A FIFO given as the log blocked forever in fopen; now it is refused.
TEST_F(LcmLogReaderTest, FifoIsRefusedWithoutBlocking) {
  const std::string path = (dir_ / "fifo.lcmlog").string();
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  try {
    LcmLogReader reader(path);
    FAIL() << "a FIFO was opened";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open log '" + path + "': not a regular file"),
              std::string::npos)
        << e.what();
  }
}

TEST_F(LcmLogReaderTest, MemoryStreamsReadTheSame) {
  std::vector<uint8_t> bytes = Event(5, 6, 1, 1, "Az");
  std::FILE* f = fmemopen(bytes.data(), bytes.size(), "rb");
  ASSERT_NE(f, nullptr);
  LcmLogReader reader(f, static_cast<int64_t>(bytes.size()), "memory");
  LogEvent e;
  EXPECT_EQ(reader.Next(&e), LogReadResult::kEvent);
  EXPECT_EQ(e.event_number, 5);
  EXPECT_EQ(reader.Next(&e), LogReadResult::kEnd);
  std::fclose(f);
}

}  // namespace
}  // namespace graspfill::io
