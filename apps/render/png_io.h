// Pictures as PNG files: 8-bit RGB out (through a temporary file renamed into place), most PNG
// kinds in (as RGBA).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sffd::gl {

struct RgbaImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;   // 4 bytes a pixel, rows from the top
  const uint8_t* pixel(int x, int y) const { return &rgba[(static_cast<size_t>(y) * width + x) * 4]; }
};

// Writes the image as an 8-bit RGB PNG; nothing is left on failure; an unwritable path is an input Error.
void writePng(const std::string& path, const RgbaImage& image);
// Reads an 8-bit (or 16-bit, reduced) gray/RGB/RGBA/palette PNG as RGBA; throws an input Error on a bad file.
RgbaImage readPng(const std::string& path);

}  // namespace sffd::gl
