#pragma once
// cylinder3's wall (radius 3 m about Z, 0-3.5 m high) as a PLY mesh of 0.25 deg facets
// over the 240 deg facing +Y: its chords lie within 7 um of the true wall. For tests that
// hand the daemon or procam-render the TRUE surface.
#include <numbers>
#include <sstream>
#include <string>

namespace procam::itest {

inline std::string cylinderPly() {
  constexpr int kAround = 960, kUp = 14;
  std::ostringstream v, f;
  v.precision(12);
  for (int i = 0; i <= kAround; ++i) {
    const double a = (-120.0 + 240.0 * i / kAround) * std::numbers::pi / 180;
    for (int j = 0; j <= kUp; ++j)
      v << 3 * std::sin(a) << ' ' << 3 * std::cos(a) << ' ' << 3.5 * j / kUp << '\n';
  }
  int faces = 0;
  for (int i = 0; i < kAround; ++i) {
    for (int j = 0; j < kUp; ++j) {
      const int k = i * (kUp + 1) + j;
      f << "3 " << k << ' ' << k + kUp + 1 << ' ' << k + 1 << '\n';
      f << "3 " << k + 1 << ' ' << k + kUp + 1 << ' ' << k + kUp + 2 << '\n';
      faces += 2;
    }
  }
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string((kAround + 1) * (kUp + 1)) +
         "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
         std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n" +
         v.str() + f.str();
}

}  // namespace procam::itest
