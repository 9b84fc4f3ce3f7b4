#pragma once
// The Wii Remote test stream: 4 IR LEDs on a cap moving on a known trajectory in front of
// the Wii camera (wiimoteCamera(), world = camera frame), projected, quantised to the
// reports' 10-bit grid and encoded as 0x33 reports at 100 Hz (the Wii Remote's rate).
// wiimote_stream_gen writes it to data/wiimote_ir_stream.csv; the tests read the stored
// file and check it against generate().
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "tracker/hid/wiimote_ir_source.hpp"

namespace procam::tracker::wiimote::testing {

// Asymmetric and not coplanar (m, cap frame): 15 cm wide, so that the 10-bit grid's
// quantisation (sigma 1/sqrt(12) px) costs a few mm at 1-1.4 m with f = 1728 px.
inline const Points3 kLeds = {Vec3(-0.08, 0, 0), Vec3(0.07, 0, 0), Vec3(0.01, -0.07, 0.03),
                              Vec3(-0.03, 0.05, 0.015)};

inline constexpr double kRateHz = 100;
inline constexpr int kReports = 300;
// Reports [kHiddenFrom, kHiddenTo) lose LED 3 (3 blobs: no pose from them).
inline constexpr int kHiddenFrom = 140, kHiddenTo = 150;

struct CapPose {
  Mat3 R;  // cap -> camera
  Vec3 t;  // cap origin, camera frame (m)
  Vec3 led(std::size_t i) const { return R * kLeds[i] + t; }
};

// Swaying 12 cm at 0.4 Hz, bobbing 5 cm at 0.3 Hz, 1.2 m +- 15 cm away at 0.25 Hz,
// turning +-12 deg at 0.35 Hz, LEDs facing the camera.
inline CapPose capAt(double t) {
  constexpr double kTwoPi = 2 * std::numbers::pi;
  const Mat3 R = (Eigen::AngleAxisd(0.21 * std::sin(kTwoPi * 0.35 * t), Vec3::UnitY()) *
                  Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitY()))
                     .toRotationMatrix();
  return {R, Vec3(0.12 * std::sin(kTwoPi * 0.4 * t), 0.05 * std::sin(kTwoPi * 0.3 * t),
                  1.2 + 0.15 * std::sin(kTwoPi * 0.25 * t))};
}

struct StreamReport {
  double time = 0;  // s
  Report report;
  Vec3 truth = Vec3::Zero();  // cap origin, camera frame (m)
};

// Blob slots do not follow the LEDs: the order rotates with the report index, and the
// size (weight) shrinks with distance as a real blob's would.
inline std::vector<StreamReport> generate() {
  const geom::CameraModel cam = wiimoteCamera();
  std::vector<StreamReport> out;
  for (int k = 0; k < kReports; ++k) {
    const double t = k / kRateHz;
    const CapPose cap = capAt(t);
    std::vector<IrBlob> blobs;
    for (std::size_t j = 0; j < kLeds.size(); ++j) {
      const std::size_t i = (j + std::size_t(k)) % kLeds.size();
      if (i == 3 && k >= kHiddenFrom && k < kHiddenTo) continue;
      const Vec3 p = cap.led(i);
      blobs.push_back({*cam.project(p), int(std::lround(4.0 * 1.2 / p.z()))});
    }
    out.push_back({t, encodeIrExtended(0, blobs), cap.t});
  }
  return out;
}

inline std::string toHex(const Report& r) {
  std::string s;
  char b[3];
  for (std::uint8_t v : r) {
    std::snprintf(b, sizeof b, "%02x", v);
    s += b;
  }
  return s;
}

inline void write(std::ostream& os, const std::vector<StreamReport>& stream) {
  os << "# Wii Remote IR stream (tests/unit/tracker/wiimote_stream.hpp): time_s, input report "
        "(hex, ID first), true cap origin x y z (m, camera frame)\n";
  char line[160];
  for (const StreamReport& r : stream) {
    std::snprintf(line, sizeof line, "%.2f,%s,%.9f,%.9f,%.9f\n", r.time, toHex(r.report).c_str(),
                  r.truth.x(), r.truth.y(), r.truth.z());
    os << line;
  }
}

// nullopt when the file is missing or a line is malformed.
inline std::optional<std::vector<StreamReport>> read(const std::string& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  std::vector<StreamReport> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string time, hex, x, y, z;
    if (!std::getline(fields, time, ',') || !std::getline(fields, hex, ',') ||
        !std::getline(fields, x, ',') || !std::getline(fields, y, ',') || !std::getline(fields, z))
      return std::nullopt;
    StreamReport r;
    r.time = std::stod(time);
    if (hex.size() % 2) return std::nullopt;
    for (std::size_t i = 0; i < hex.size(); i += 2)
      r.report.push_back(std::uint8_t(std::stoul(hex.substr(i, 2), nullptr, 16)));
    r.truth = Vec3(std::stod(x), std::stod(y), std::stod(z));
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace procam::tracker::wiimote::testing
