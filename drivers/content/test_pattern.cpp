#include "test_pattern.hpp"

namespace procam::content {

RgbImage renderTestPattern(std::string_view name, int width, int height, int cell) {
  RgbImage img;
  img.width = width;
  img.height = height;
  const uint8_t background = name == "white" ? 255 : 0;
  img.pixels.assign(static_cast<size_t>(width) * height * 3, background);
  auto set = [&](int x, int y) {
    uint8_t* p = &img.pixels[(static_cast<size_t>(y) * width + x) * 3];
    p[0] = p[1] = p[2] = 255;
  };
  const int cx = (width - 1) / 2;
  const int cy = (height - 1) / 2;
  auto onLine = [&](int v, int centre, int last) {
    if (v == 0 || v == last || v == centre) return true;
    return name == "grid" && cell > 0 && (v - centre) % cell == 0;
  };
  if (name == "grid" || name == "crosshair") {
    for (int y = 0; y < height; ++y) {
      const bool row = onLine(y, cy, height - 1);
      for (int x = 0; x < width; ++x) {
        if (row || onLine(x, cx, width - 1)) set(x, y);
      }
    }
  }
  return img;
}

}  // namespace procam::content
