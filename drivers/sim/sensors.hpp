#pragma once
// Mock tilt sensors and IR trackers (SCENE-FORMAT.md, "Sensor models").
//
// Tilt sensor: specific force in the sensor frame, f = R_sensor<-world * (a + (0, 0, +g))
// with a the projector centre's acceleration over the sample period (a central second
// difference of the trajectory, 1/rate apart), + bias + white noise with
// sigma = noise_density * sqrt(rate / 2) per axis, clamped to the full scale; in m/s^2
// (default) or g. Gyroscope (a tilt sensor's `gyro`): the sensor's angular velocity in
// its own frame (from the orientation 1/rate before and after), + constant bias + a bias
// random walk + white noise, clamped; rad/s. Tracker: true tracked position + isotropic
// Gaussian noise. Noise for sample k = round(time * rate) depends only on
// (seed, device name, k), so a sample is the same whoever asks and in which order; so
// does the bias walk (its steps are such samples, summed from k = 0).
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
  Vec3 value = Vec3::Zero();   // what the sensor reports (units of the scene)
  Vec3 truth = Vec3::Zero();   // gravity reaction only: no motion, bias, noise or clamp
  Vec3 motion = Vec3::Zero();  // the motion's part of the specific force (units of the scene)
};

struct GyroSample {
  double time = 0;
  Vec3 value = Vec3::Zero();  // what the gyroscope reports, rad/s, sensor frame
  Vec3 truth = Vec3::Zero();  // the true angular velocity: no bias, no noise, no clamp
  Vec3 bias = Vec3::Zero();   // the bias at this time (constant + walk), rad/s
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

// kNotFound for no such sensor or one without a gyroscope.
Result<GyroSample> sampleGyro(const Scene& scene, std::string_view sensor, double time,
                              std::uint64_t seed = 1, bool noise = true);

Result<TrackerSample> sampleTracker(const Scene& scene, std::string_view tracker, double time,
                                    std::uint64_t seed = 1, bool noise = true);

// Per-sample noise sigma of a tilt sensor, in g.
double tiltNoiseSigmaG(const TiltSensorSpec& spec);

}  // namespace procam::sim
