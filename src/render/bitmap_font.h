// A 1-bit bitmap font for labels in pictures (internal to render/).
//
// Text in film strips and videos is drawn on the CPU into an Image, so labels need no GL
// context and come out identical on every machine. The glyphs are MuJoCo's own built-in
// font (see bitmap_font.cc for how the tables were made), so labels match what MuJoCo's
// viewer shows.
#pragma once

#include <cstdint>

#include "render/image.h"

namespace diverse {

struct BitmapFont {
  int rows = 0;                           // glyph cell height, pixels
  const std::uint8_t* widths = nullptr;   // advance width, pixels, of chars 32..126
  const std::uint32_t* bits = nullptr;    // rows per glyph, top row first; bit x = column x
};

const BitmapFont& bitmap_font(FontSize size);

}  // namespace diverse
