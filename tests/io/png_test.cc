// SPDX-License-Identifier: BSD-3-Clause
// PNG pictures: what is written reads back (through Open3D's reader) pixel
// for pixel, the same image gives the same bytes, errors name the path.
#include "graspfill/io/png.hpp"

#include <gtest/gtest.h>
#include <open3d/geometry/Image.h>
#include <open3d/io/ImageIO.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

namespace graspfill::io {
namespace {

namespace fs = std::filesystem;

class PngTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(GRASPFILL_BINARY_DIR) / "test_tmp" / "io_png" /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

// A gradient with a different value in every channel of every pixel.
RgbImage Gradient(int width, int height) {
  RgbImage image;
  image.width = width;
  image.height = height;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      image.rgb.push_back(static_cast<uint8_t>(x * 7));
      image.rgb.push_back(static_cast<uint8_t>(y * 5));
      image.rgb.push_back(static_cast<uint8_t>((x + y) * 3));
    }
  }
  return image;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST_F(PngTest, ReadsBackPixelForPixel) {
  const RgbImage image = Gradient(37, 21);
  WritePng(Path("g.png"), image);
  open3d::geometry::Image back;
  ASSERT_TRUE(open3d::io::ReadImage(Path("g.png"), back));
  ASSERT_EQ(back.width_, 37);
  ASSERT_EQ(back.height_, 21);
  ASSERT_EQ(back.num_of_channels_, 3);
  ASSERT_EQ(back.bytes_per_channel_, 1);
  EXPECT_EQ(std::vector<uint8_t>(back.data_.begin(), back.data_.end()), image.rgb);
  // PNG's signature, and nothing left beside it.
  EXPECT_EQ(ReadBytes(Path("g.png")).substr(1, 3), "PNG");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

TEST_F(PngTest, SameImageGivesSameBytes) {
  WritePng(Path("a.png"), Gradient(50, 40));
  WritePng(Path("b.png"), Gradient(50, 40));
  EXPECT_EQ(ReadBytes(Path("a.png")), ReadBytes(Path("b.png")));
}

TEST_F(PngTest, ErrorsNameThePath) {
  const std::string missing_dir = Path("no/such/dir/x.png");
  try {
    WritePng(missing_dir, Gradient(4, 4));
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing_dir), std::string::npos) << e.what();
  }
  EXPECT_THROW(WritePng(Path("empty.png"), RgbImage{}), std::runtime_error);
  RgbImage short_buffer = Gradient(4, 4);
  short_buffer.rgb.pop_back();
  EXPECT_THROW(WritePng(Path("short.png"), short_buffer), std::runtime_error);
  EXPECT_FALSE(fs::exists(Path("empty.png")));
  EXPECT_FALSE(fs::exists(Path("short.png")));
}

}  // namespace
}  // namespace graspfill::io
