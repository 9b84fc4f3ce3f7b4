#pragma once
// Units and physical constants, defined once for every layer (ARCHITECTURE.md,
// "Frames and conventions"): radians inside the code, degrees only at the user's
// edge; specific force in m/s^2, with g the standard gravity.
#include <numbers>

namespace procam {

// Standard acceleration of gravity, m/s^2 per g (3rd CGPM, 1901).
inline constexpr double kStandardGravity = 9.80665;

inline constexpr double degToRad(double degrees) {
  return degrees * (std::numbers::pi / 180.0);
}
inline constexpr double radToDeg(double radians) {
  return radians * (180.0 / std::numbers::pi);
}

// One degree in radians: `30 * kDeg` reads as thirty degrees.
inline constexpr double kDeg = degToRad(1);

}  // namespace procam
