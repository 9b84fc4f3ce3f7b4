#pragma once
// Alignment patterns shown on projector outputs: grid, crosshair, white,
// black ("off" shows black). 8-bit RGB, pixel centres at integer coordinates.
#include <cstdint>
#include <string_view>
#include <vector>

namespace procam::content {

struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> pixels;  // row-major, 3 bytes per pixel

  uint8_t at(int x, int y, int channel) const { return pixels[(y * width + x) * 3 + channel]; }
};

// Grid lines every `cell` pixels through the centre lines, both borders
// included; the crosshair is the two centre lines and the border.
RgbImage renderTestPattern(std::string_view name, int width, int height, int cell = 64);

}  // namespace procam::content
