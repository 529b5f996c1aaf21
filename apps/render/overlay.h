// The renderer's 2-D overlay (captions, legend): coloured quads in pixels (origin top left) and text
// in a 5x7 bitmap font (overlay.cpp), turned into triangles the overlay program draws.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace sffd::gl {

// The glyph's seven rows of five cells from the top, separated by spaces ('#' set); nullptr for a
// space or a character the font lacks (drawn blank). Lower case is drawn as upper case.
const char* glyphRows(char c);

struct OverlayVertex {
  float x, y;
  float r, g, b, a;
};

struct Overlay {
  std::vector<OverlayVertex> v;
  void quad(float x0, float y0, float x1, float y1, glm::vec4 top, glm::vec4 bottom) {
    OverlayVertex a{x0, y0, top.r, top.g, top.b, top.a}, b{x1, y0, top.r, top.g, top.b, top.a};
    OverlayVertex c{x1, y1, bottom.r, bottom.g, bottom.b, bottom.a}, d{x0, y1, bottom.r, bottom.g, bottom.b, bottom.a};
    v.insert(v.end(), {a, b, c, a, c, d});
  }
  void quad(float x0, float y0, float x1, float y1, glm::vec4 color) { quad(x0, y0, x1, y1, color, color); }
  // Text with its top-left corner at (x, y), glyph cells of `scale` pixels, 6 cells an advance.
  void text(const std::string& s, float x, float y, float scale, glm::vec4 color) {
    for (size_t i = 0; i < s.size(); ++i) {
      const char* rows = glyphRows(s[i]);
      if (!rows) continue;
      float gx = x + static_cast<float>(i) * 6 * scale;
      for (int r = 0; r < 7; ++r)
        for (int c = 0; c < 5; ++c)
          if (rows[r * 6 + c] == '#')
            quad(gx + c * scale, y + r * scale, gx + (c + 1) * scale, y + (r + 1) * scale, color);
    }
  }
  static float textWidth(const std::string& s, float scale) {
    return s.empty() ? 0 : (static_cast<float>(s.size()) * 6 - 1) * scale;
  }
};

}  // namespace sffd::gl
