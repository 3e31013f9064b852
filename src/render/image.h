// A small RGB image, PNG files, compositing and text labels.
//
// Pictures are assembled on the CPU: the offscreen renderer produces one Image per view,
// and film strips and video frames paste those tiles onto a canvas and draw labels with a
// built-in bitmap font (MuJoCo's own glyphs), so no GL context is needed past rendering.
// Pixels are 8-bit RGB, rows stored top to bottom (the order of PNG files and ffmpeg's
// rawvideo input, the opposite of glReadPixels). PNG input and output use libpng's
// simplified API, which reports errors by return value rather than longjmp.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace diverse {

struct Rgb {
  std::uint8_t r = 0;
  std::uint8_t g = 0;
  std::uint8_t b = 0;
  bool operator==(const Rgb&) const = default;
};

class Image {
 public:
  Image() = default;
  // Throws std::invalid_argument on a negative size.
  Image(int width, int height, Rgb fill = Rgb{255, 255, 255});

  int width() const { return width_; }
  int height() const { return height_; }
  bool empty() const { return width_ == 0 || height_ == 0; }
  // width * height * 3 bytes, row-major, top row first.
  std::uint8_t* data() { return pixels_.data(); }
  const std::uint8_t* data() const { return pixels_.data(); }

  // (x, y) in pixels from the top-left corner; must lie inside the image.
  Rgb pixel(int x, int y) const;
  void set_pixel(int x, int y, Rgb color);

  void fill(Rgb color);
  // Fills the rectangle with top-left corner (x, y), clipped to the image.
  void fill_rect(int x, int y, int width, int height, Rgb color);
  // Copies source with its top-left corner at (x, y), clipped to the image.
  void paste(const Image& source, int x, int y);

  bool operator==(const Image&) const = default;

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<std::uint8_t> pixels_;
};

// Line heights 15, 22 and 28 pixels (MuJoCo's font at font scales 100, 150 and 200).
enum class FontSize { kSmall, kMedium, kLarge };
enum class Align { kLeft, kCenter, kRight };

// Width and height in pixels of a single line of text.
int text_width(std::string_view text, FontSize size);
int text_height(FontSize size);

// Draws one line of text whose top edge is at y and whose left edge, centre or right edge
// (per align) is at x, clipped to the image. Characters outside printable ASCII show as '?'.
void draw_text(Image& image, std::string_view text, int x, int y, Rgb color,
               FontSize size = FontSize::kMedium, Align align = Align::kLeft);

// Writes an 8-bit RGB PNG. Throws UserError naming the path if it cannot be written.
void write_png(const std::string& path, const Image& image);
// Reads any PNG (grey, palette, alpha and 16-bit inputs are converted to 8-bit RGB; alpha
// is composited on white). Throws UserError naming the path if it cannot be read.
Image read_png(const std::string& path);

}  // namespace diverse
