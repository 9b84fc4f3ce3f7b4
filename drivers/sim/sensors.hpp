#pragma once
// Mock tilt sensors and IR trackers (SCENE-FORMAT.md, "Sensor models").
//
// Tilt sensor: specific force in the sensor frame, quasi-static (the trajectory's
// own accelerations are not modelled): f = R_sensor<-world * (0, 0, +g) + bias +
// white noise with sigma = noise_density * sqrt(rate / 2) per axis, clamped to the
// full scale; in m/s^2 (default) or g. Tracker: true tracked position + isotropic
// Gaussian noise. Noise for sample k = round(time * rate) depends only on
// (seed, device name, k), so a sample is the same whoever asks and in which order.
#include <cstdint>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "core/units.hpp"
#include "sim/scene.hpp"

namespace procam::sim {

using procam::kStandardGravity;  // core/units.hpp

struct TiltSample {
  double time = 0;
  Vec3 value = Vec3::Zero();  // what the sensor reports (units of the scene)
  Vec3 truth = Vec3::Zero();  // gravity reaction only: no bias, no noise, no clamp
};

struct TrackerSample {
  double time = 0;
  Vec3 position = Vec3::Zero();  // measured, world metres
  Vec3 truth = Vec3::Zero();
};

Result<TiltSample> sampleTilt(const Scene& scene, std::string_view sensor, double time,
                              std::uint64_t seed = 1, bool noise = true);
// All samples k / rate inside [t_begin, t_end].
Result<std::vector<TiltSample>> sampleTiltSeries(const Scene& scene, std::string_view sensor,
                                                 double t_begin, double t_end,
                                                 std::uint64_t seed = 1, bool noise = true);

Result<TrackerSample> sampleTracker(const Scene& scene, std::string_view tracker, double time,
                                    std::uint64_t seed = 1, bool noise = true);

// Per-sample noise sigma of a tilt sensor, in g.
double tiltNoiseSigmaG(const TiltSensorSpec& spec);

}  // namespace procam::sim
