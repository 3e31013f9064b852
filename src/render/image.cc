#include "render/image.h"

#include <png.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "core/error.h"
#include "render/bitmap_font.h"

namespace diverse {
namespace {

constexpr int kFirstGlyph = 32;  // ' '
constexpr int kLastGlyph = 126;  // '~'

int glyph_index(char c) {
  const int code = static_cast<unsigned char>(c);
  return (code < kFirstGlyph || code > kLastGlyph ? '?' : code) - kFirstGlyph;
}

}  // namespace

Image::Image(int width, int height, Rgb fill) : width_(width), height_(height) {
  if (width < 0 || height < 0) {
    throw std::invalid_argument("Image: negative size " + std::to_string(width) + "x" +
                                std::to_string(height));
  }
  pixels_.resize(static_cast<std::size_t>(width) * height * 3);
  this->fill(fill);
}

Rgb Image::pixel(int x, int y) const {
  const std::uint8_t* p = &pixels_[(static_cast<std::size_t>(y) * width_ + x) * 3];
  return {p[0], p[1], p[2]};
}

void Image::set_pixel(int x, int y, Rgb color) {
  std::uint8_t* p = &pixels_[(static_cast<std::size_t>(y) * width_ + x) * 3];
  p[0] = color.r;
  p[1] = color.g;
  p[2] = color.b;
}

void Image::fill(Rgb color) { fill_rect(0, 0, width_, height_, color); }

void Image::fill_rect(int x, int y, int width, int height, Rgb color) {
  const int x0 = std::max(x, 0);
  const int y0 = std::max(y, 0);
  const int x1 = std::min(x + width, width_);
  const int y1 = std::min(y + height, height_);
  for (int row = y0; row < y1; ++row) {
    for (int col = x0; col < x1; ++col) set_pixel(col, row, color);
  }
}

void Image::paste(const Image& source, int x, int y) {
  const int x0 = std::max(x, 0);
  const int x1 = std::min(x + source.width(), width_);
  if (x1 <= x0) return;
  const std::size_t bytes = static_cast<std::size_t>(x1 - x0) * 3;
  for (int row = std::max(y, 0); row < std::min(y + source.height(), height_); ++row) {
    const std::uint8_t* from =
        source.data() + (static_cast<std::size_t>(row - y) * source.width() + (x0 - x)) * 3;
    std::memcpy(&pixels_[(static_cast<std::size_t>(row) * width_ + x0) * 3], from, bytes);
  }
}

int text_width(std::string_view text, FontSize size) {
  const BitmapFont& font = bitmap_font(size);
  int width = 0;
  for (char c : text) width += font.widths[glyph_index(c)];
  return width;
}

int text_height(FontSize size) { return bitmap_font(size).rows; }

void draw_text(Image& image, std::string_view text, int x, int y, Rgb color, FontSize size,
               Align align) {
  const BitmapFont& font = bitmap_font(size);
  if (align == Align::kCenter) x -= text_width(text, size) / 2;
  if (align == Align::kRight) x -= text_width(text, size);
  for (char c : text) {
    const int glyph = glyph_index(c);
    const int width = font.widths[glyph];
    for (int row = 0; row < font.rows; ++row) {
      const std::uint32_t bits = font.bits[glyph * font.rows + row];
      const int py = y + row;
      if (bits == 0 || py < 0 || py >= image.height()) continue;
      for (int col = 0; col < width; ++col) {
        const int px = x + col;
        if ((bits >> col & 1u) && px >= 0 && px < image.width()) image.set_pixel(px, py, color);
      }
    }
    x += width;
  }
}

void write_png(const std::string& path, const Image& image) {
  if (image.empty()) throw UserError(path + ": cannot write an empty image");
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width());
  png.height = static_cast<png_uint_32>(image.height());
  png.format = PNG_FORMAT_RGB;
  if (!png_image_write_to_file(&png, path.c_str(), 0, image.data(), 0, nullptr)) {
    const std::string reason = png.message;
    png_image_free(&png);
    throw UserError(path + ": cannot write PNG: " + reason);
  }
}

Image read_png(const std::string& path) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    const std::string reason = png.message;
    png_image_free(&png);
    throw UserError(path + ": cannot read PNG: " + reason);
  }
  png.format = PNG_FORMAT_RGB;
  Image image(static_cast<int>(png.width), static_cast<int>(png.height));
  const png_color white{255, 255, 255};
  if (!png_image_finish_read(&png, &white, image.data(), 0, nullptr)) {
    const std::string reason = png.message;
    png_image_free(&png);
    throw UserError(path + ": cannot read PNG: " + reason);
  }
  return image;
}

}  // namespace diverse
