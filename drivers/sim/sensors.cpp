#include "sim/sensors.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <mutex>
#include <random>
#include <string>
#include <utility>
#include <vector>

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
  // Specific force: the reaction to gravity, +1 g along world +Z, plus the projector
  // centre's acceleration over one sample period.
  const Vec3 truth_g = s->sensor_from_world * Vec3::UnitZ();
  const double period = 1.0 / spec->rate_hz;
  const auto centre = [&](double t) {
    return scene.at(t).projector(spec->projector)->model.pose.center();
  };
  Vec3 acceleration =
      (centre(time + period) - 2 * state.projector(spec->projector)->model.pose.center() +
       centre(time - period)) /
      (period * period);
  // A still or steadily moving projector: what is left is the rounding of the poses'
  // centres, far below any accelerometer's resolution (1e-6 m/s^2 is 0.1 ug).
  if (acceleration.norm() < 1e-6) acceleration.setZero();
  const Vec3 motion_g = s->sensor_from_world * acceleration / kStandardGravity;
  Vec3 measured_g = truth_g + motion_g + 1e-3 * spec->bias_mg;
  if (noise) {
    auto rng = sampleRng(seed, spec->name, time, spec->rate_hz);
    measured_g += tiltNoiseSigmaG(*spec) * gaussian3(rng);
  }
  if (spec->full_scale_g > 0)
    measured_g = measured_g.cwiseMax(-spec->full_scale_g).cwiseMin(spec->full_scale_g);
  const double unit = spec->report_in_g ? 1.0 : kStandardGravity;
  return TiltSample{time, unit * measured_g, unit * truth_g, unit * motion_g};
}

namespace {

// The gyroscope's bias walk at sample k: the sum of k Gaussian steps of sigma `step`
// (rad/s), each step sample i's own deterministic draw. Sums are kept per sensor and seed
// and extended on demand, so a long series costs one step per sample.
Vec3 biasWalk(std::uint64_t seed, const std::string& sensor, double rate, long long k,
              double step) {
  if (k <= 0 || step <= 0) return Vec3::Zero();
  static std::mutex mutex;
  static std::map<std::pair<std::uint64_t, std::string>, std::vector<Vec3>> sums;
  const std::lock_guard lock(mutex);
  std::vector<Vec3>& sum = sums[{seed, sensor + "#gyro-walk"}];
  if (sum.empty()) sum.push_back(Vec3::Zero());
  constexpr long long kMaxSteps = 100'000'000;
  k = std::min(k, kMaxSteps);
  while (static_cast<long long>(sum.size()) <= k) {
    const double t = static_cast<double>(sum.size()) / rate;
    auto rng = sampleRng(seed, sensor + "#gyro-walk", t, rate);
    sum.push_back(sum.back() + gaussian3(rng));
  }
  return step * sum[static_cast<std::size_t>(k)];
}

// The angular velocity of a frame whose rotation from the world is R(t), in that frame:
// R' = -[w]x R, so R(t + h) R(t - h)^T = exp(-2h [w]x).
Vec3 angularVelocity(const Mat3& before, const Mat3& after, double h) {
  const Eigen::AngleAxisd turn(Mat3(after * before.transpose()));
  return -turn.angle() * turn.axis() / (2 * h);
}

}  // namespace

Result<GyroSample> sampleGyro(const Scene& scene, std::string_view sensor, double time,
                              std::uint64_t seed, bool noise) {
  const TiltSensorSpec* spec = findSensor(scene, sensor);
  if (!spec || !spec->gyro) {
    return fail(ErrorCode::kNotFound,
                "no tilt sensor with a gyroscope named '" + std::string(sensor) + "'");
  }
  if (!std::isfinite(time)) return fail(ErrorCode::kInvalidInput, "sample time must be finite");
  const GyroSpec& g = *spec->gyro;
  const double h = 0.5 / spec->rate_hz;
  const Mat3 before = scene.at(time - h).tiltSensor(sensor)->sensor_from_world;
  const Mat3 after = scene.at(time + h).tiltSensor(sensor)->sensor_from_world;
  GyroSample out;
  out.time = time;
  out.truth = angularVelocity(before, after, h);
  const auto k = static_cast<long long>(std::llround(time * spec->rate_hz));
  out.bias =
      degToRad(1.0) * g.bias_dps + biasWalk(seed, spec->name, spec->rate_hz, k,
                                            degToRad(g.bias_walk_dps) / std::sqrt(spec->rate_hz));
  out.value = out.truth + out.bias;
  if (noise) {
    auto rng = sampleRng(seed, spec->name + "#gyro", time, spec->rate_hz);
    out.value += degToRad(g.noise_density_dps) * std::sqrt(0.5 * spec->rate_hz) * gaussian3(rng);
  }
  if (g.full_scale_dps > 0) {
    const double limit = degToRad(g.full_scale_dps);
    out.value = out.value.cwiseMax(-limit).cwiseMin(limit);
  }
  return out;
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
