#include "sim/sensors.hpp"

#include <cmath>
#include <random>
#include <string>

namespace procam::sim {

namespace {

std::mt19937_64 sampleRng(std::uint64_t seed, std::string_view device, double time, double rate) {
  const auto k = static_cast<std::uint64_t>(std::llround(time * rate));
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a of the device name
  for (const char c : device) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(h),    static_cast<std::uint32_t>(h >> 32),
                    static_cast<std::uint32_t>(k),    static_cast<std::uint32_t>(k >> 32)};
  return std::mt19937_64(seq);
}

Vec3 gaussian3(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const double x = normal(rng);
  const double y = normal(rng);
  const double z = normal(rng);
  return {x, y, z};
}

const TiltSensorSpec* findSensor(const Scene& scene, std::string_view name) {
  for (const auto& s : scene.tiltSensors()) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

}  // namespace

double tiltNoiseSigmaG(const TiltSensorSpec& spec) {
  return spec.noise_density_ug * 1e-6 * std::sqrt(0.5 * spec.rate_hz);
}

Result<TiltSample> sampleTilt(const Scene& scene, std::string_view sensor, double time,
                              std::uint64_t seed, bool noise) {
  const TiltSensorSpec* spec = findSensor(scene, sensor);
  if (!spec)
    return fail(ErrorCode::kNotFound, "no tilt sensor named '" + std::string(sensor) + "'");
  if (!std::isfinite(time)) return fail(ErrorCode::kInvalidInput, "sample time must be finite");
  const SceneState state = scene.at(time);
  const TiltSensorState* s = state.tiltSensor(sensor);
  // Specific force at rest: the reaction to gravity, +1 g along world +Z.
  const Vec3 truth_g = s->sensor_from_world * Vec3::UnitZ();
  Vec3 measured_g = truth_g + 1e-3 * spec->bias_mg;
  if (noise) {
    auto rng = sampleRng(seed, spec->name, time, spec->rate_hz);
    measured_g += tiltNoiseSigmaG(*spec) * gaussian3(rng);
  }
  if (spec->full_scale_g > 0)
    measured_g = measured_g.cwiseMax(-spec->full_scale_g).cwiseMin(spec->full_scale_g);
  const double unit = spec->report_in_g ? 1.0 : kStandardGravity;
  return TiltSample{time, unit * measured_g, unit * truth_g};
}

Result<std::vector<TiltSample>> sampleTiltSeries(const Scene& scene, std::string_view sensor,
                                                 double t_begin, double t_end, std::uint64_t seed,
                                                 bool noise) {
  const TiltSensorSpec* spec = findSensor(scene, sensor);
  if (!spec)
    return fail(ErrorCode::kNotFound, "no tilt sensor named '" + std::string(sensor) + "'");
  if (!std::isfinite(t_begin) || !std::isfinite(t_end) || t_end < t_begin)
    return fail(ErrorCode::kInvalidInput, "need finite t_begin <= t_end");
  const auto first = static_cast<long long>(std::ceil(t_begin * spec->rate_hz - 1e-9));
  const auto last = static_cast<long long>(std::floor(t_end * spec->rate_hz + 1e-9));
  if (last - first > 10'000'000) return fail(ErrorCode::kInvalidInput, "too many samples");
  std::vector<TiltSample> out;
  for (long long k = first; k <= last; ++k) {
    auto s = sampleTilt(scene, sensor, static_cast<double>(k) / spec->rate_hz, seed, noise);
    if (!s) return tl::unexpected(s.error());
    out.push_back(*s);
  }
  return out;
}

Result<TrackerSample> sampleTracker(const Scene& scene, std::string_view tracker, double time,
                                    std::uint64_t seed, bool noise) {
  const TrackerSpec* spec = nullptr;
  for (const auto& t : scene.trackers()) {
    if (t.name == tracker) spec = &t;
  }
  if (!spec) return fail(ErrorCode::kNotFound, "no tracker named '" + std::string(tracker) + "'");
  if (!std::isfinite(time)) return fail(ErrorCode::kInvalidInput, "sample time must be finite");
  TrackerSample out;
  out.time = time;
  out.truth = spec->trajectory.empty() ? scene.viewerPosition(time)
                                       : scene.trajectory(spec->trajectory)->centerAt(time);
  out.position = out.truth;
  if (noise) {
    auto rng = sampleRng(seed, spec->name, time, spec->rate_hz);
    out.position += spec->noise_sigma_m * gaussian3(rng);
  }
  return out;
}

}  // namespace procam::sim
