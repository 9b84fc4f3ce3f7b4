#pragma once
// Reflected binary (Gray) code: neighbouring cells differ in exactly one bit, so a
// camera pixel on a stripe edge decodes to one of the two adjacent cells
// ([Raskar02] §4.1.1, "binary-coding the projector illuminated pixels ... log2(n) frames").
#include <bit>
#include <cstdint>

namespace procam::sl {

constexpr std::uint32_t toGray(std::uint32_t binary) {
  return binary ^ (binary >> 1);
}

constexpr std::uint32_t fromGray(std::uint32_t gray) {
  gray ^= gray >> 16;
  gray ^= gray >> 8;
  gray ^= gray >> 4;
  gray ^= gray >> 2;
  gray ^= gray >> 1;
  return gray;
}

// Bits needed to give every one of `cells` cells its own code (0 for one cell).
constexpr int bitsFor(std::uint32_t cells) {
  return cells <= 1 ? 0 : static_cast<int>(std::bit_width(cells - 1));
}

}  // namespace procam::sl
