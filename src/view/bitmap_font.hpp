// SPDX-License-Identifier: BSD-3-Clause
// A 5 x 7 pixel font for the titles and the legend of the pictures: no font
// file to find at run time, the same pixels on every machine.
#pragma once

#include <string>

#include "graspfill/core/provenance_colors.hpp"
#include "graspfill/types.hpp"

namespace graspfill::view {

/// Pixels of one glyph cell at scale 1, the gap to the next included.
constexpr int kGlyphAdvance = 6;
constexpr int kGlyphHeight = 7;

/// Width of `text` drawn at `scale` [pixels].
int TextWidth(const std::string& text, int scale);

/// Draws `text` with its top-left corner at (x, y), each font pixel a
/// `scale` x `scale` block; pixels outside the image are skipped.
/// Lowercase letters, digits, space and . , - _ : ( ) / % + are drawn;
/// uppercase as lowercase; any other character as '?'.
void DrawText(const std::string& text, int x, int y, int scale, const Rgb8& color, RgbImage* image);

/// `text` cut to at most `max_width` pixels at `scale`, ".." marking a cut.
std::string FitText(const std::string& text, int max_width, int scale);

}  // namespace graspfill::view
