#pragma once
// The built-in 5x7 bitmap font used for contact-sheet labels and plot text.
#include <cstdint>
#include <string>

namespace femto::font {

constexpr int kGlyphW = 5, kGlyphH = 7, kAdvance = kGlyphW + 1;

/// The 7 rows of glyph c, top row first, bit 4 = leftmost column. Covers digits, a-z (A-Z are
/// drawn lower case), space and . , - + = : / ( ) _ % ; any other character gives '?'.
const uint8_t* glyph_rows(char c);

/// Width in pixels of `text` drawn at `scale` (no gap after the last glyph); 0 for "".
int text_width(const std::string& text, int scale);

/// Sets the pixels of `text` in an RGB8 image (width*height*3, top row first) to `rgb`, the
/// top-left corner of the first glyph at (x, y); clipped to the image. `vertical` draws the text
/// rotated 90 degrees counter-clockwise, reading bottom to top, its bottom-left corner at (x, y).
void draw_text(uint8_t* image, int width, int height, int x, int y, const std::string& text,
               int scale, const uint8_t rgb[3], bool vertical = false);

}  // namespace femto::font
