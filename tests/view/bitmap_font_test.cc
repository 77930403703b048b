// SPDX-License-Identifier: BSD-3-Clause
// The pictures' font: widths, cutting to fit, drawing clipped at the edges.
#include "bitmap_font.hpp"

#include <gtest/gtest.h>

namespace graspfill::view {
namespace {

RgbImage Blank(int width, int height) {
  RgbImage image;
  image.width = width;
  image.height = height;
  image.rgb.assign(static_cast<size_t>(width) * height * 3, 255);
  return image;
}

int Inked(const RgbImage& image) {
  int n = 0;
  for (size_t i = 0; i < image.rgb.size(); i += 3) n += image.rgb[i] == 0;
  return n;
}

TEST(BitmapFontTest, WidthAndFit) {
  EXPECT_EQ(TextWidth("abc", 2), 3 * kGlyphAdvance * 2);
  EXPECT_EQ(FitText("observed", 1000, 2), "observed");
  // 5 cells at scale 1: three characters and the mark of the cut.
  EXPECT_EQ(FitText("symmetry fill", 5 * kGlyphAdvance, 1), "sym..");
  EXPECT_LE(TextWidth(FitText("a long title for a narrow view", 100, 2), 2), 100);
}

TEST(BitmapFontTest, DrawsGlyphsCaseBlindUnknownAsQuestionMark) {
  const Rgb8 black{0, 0, 0};
  RgbImage lower = Blank(40, 10), upper = Blank(40, 10), unknown = Blank(40, 10), mark = Blank(40, 10);
  DrawText("ply", 1, 1, 1, black, &lower);
  DrawText("PLY", 1, 1, 1, black, &upper);
  EXPECT_GT(Inked(lower), 10);
  EXPECT_EQ(lower.rgb, upper.rgb);
  DrawText("#", 1, 1, 1, black, &unknown);
  DrawText("?", 1, 1, 1, black, &mark);
  EXPECT_GT(Inked(mark), 0);
  EXPECT_EQ(unknown.rgb, mark.rgb);
  // A space draws nothing.
  RgbImage space = Blank(40, 10);
  DrawText("   ", 1, 1, 1, black, &space);
  EXPECT_EQ(Inked(space), 0);
}

TEST(BitmapFontTest, ClippedAtTheEdges) {
  RgbImage image = Blank(8, 8);
  DrawText("ooo past the edge", -4, -4, 2, {0, 0, 0}, &image);
  EXPECT_GT(Inked(image), 0);
  EXPECT_EQ(image.rgb.size(), 8u * 8u * 3u);
}

}  // namespace
}  // namespace graspfill::view
