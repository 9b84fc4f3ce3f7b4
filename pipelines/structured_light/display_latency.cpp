#include "display_latency.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace procam::sl {

namespace {

double median(std::vector<double> v) {
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  const double hi = v[mid];
  if (v.size() % 2 == 1) return hi;
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)));
}

std::vector<double> levels(const std::vector<BrightnessSample>& s, std::size_t begin,
                           std::size_t end) {
  std::vector<double> out;
  for (std::size_t i = begin; i < end; ++i) out.push_back(s[i].brightness);
  return out;
}

// Robust sigma (1.4826 * median absolute deviation) of two groups, each about
// its own median.
double pooledSigma(const std::vector<double>& a, double ma, const std::vector<double>& b,
                   double mb) {
  std::vector<double> dev;
  for (double x : a) dev.push_back(std::abs(x - ma));
  for (double x : b) dev.push_back(std::abs(x - mb));
  return 1.4826 * median(std::move(dev));
}

Result<void> validate(const std::vector<BrightnessSample>& samples, double shown) {
  if (!std::isfinite(shown)) return fail(ErrorCode::kInvalidInput, "the show time is not finite");
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!std::isfinite(samples[i].time) || !std::isfinite(samples[i].brightness)) {
      return fail(ErrorCode::kInvalidInput, "sample " + std::to_string(i) + " is not finite");
    }
    if (i > 0 && !(samples[i].time > samples[i - 1].time)) {
      return fail(ErrorCode::kInvalidInput,
                  "sample times must increase (sample " + std::to_string(i) + ")");
    }
  }
  return {};
}

std::size_t countBefore(const std::vector<BrightnessSample>& samples, double shown) {
  return static_cast<std::size_t>(
      std::find_if(samples.begin(), samples.end(),
                   [shown](const BrightnessSample& s) { return s.time >= shown; }) -
      samples.begin());
}

}  // namespace

Result<Transition> findTransition(const std::vector<BrightnessSample>& samples, double shown,
                                  const TransitionOptions& options) {
  if (auto ok = validate(samples, shown); !ok) return tl::unexpected(ok.error());
  const std::size_t k = static_cast<std::size_t>(std::max(1, options.settled_samples));
  const std::size_t n = samples.size();
  const std::size_t n_old = countBefore(samples, shown);
  if (n_old == 0) {
    return fail(ErrorCode::kInvalidInput, "no sample before the switch gives the old level");
  }
  if (n - n_old < k) {
    return fail(ErrorCode::kInvalidInput,
                "fewer than " + std::to_string(k) + " samples after the switch give the new level");
  }
  const std::vector<double> old_v = levels(samples, 0, n_old);
  const std::vector<double> new_v = levels(samples, n - k, n);
  Transition t;
  t.old_level = median(old_v);
  t.new_level = median(new_v);
  t.noise = pooledSigma(old_v, t.old_level, new_v, t.new_level);
  const double needed = std::max(options.min_contrast, options.min_snr * t.noise);

  double largest = 0;
  for (std::size_t i = n_old; i < n; ++i) {
    largest = std::max(largest, std::abs(samples[i].brightness - t.old_level));
  }
  if (largest < needed) {
    return fail(ErrorCode::kIllConditioned, "no change seen: the level moved by at most " +
                                                std::to_string(largest) + " (needs " +
                                                std::to_string(needed) + ", noise sigma " +
                                                std::to_string(t.noise) + ")");
  }
  const double contrast = t.new_level - t.old_level;
  if (std::abs(contrast) < needed) {
    return fail(ErrorCode::kNotFound,
                "the change did not settle at a new level by the last sample");
  }
  auto u = [&](std::size_t i) { return (samples[i].brightness - t.old_level) / contrast; };
  // The first sample after which every one is past the midpoint.
  std::size_t first = n;
  while (first > n_old && u(first - 1) > 0.5) --first;
  if (first == n) {
    return fail(ErrorCode::kNotFound, "the last sample is not past the midpoint of the levels");
  }
  // The change lies after the previous sample and after the switch was shown.
  const std::size_t prev = first - 1;
  const double lo = std::max(samples[prev].time, shown);
  const double up = u(prev), uc = u(first);
  const double f = uc > up ? std::clamp((0.5 - up) / (uc - up), 0.0, 1.0) : 0.0;
  t.first_new = static_cast<int>(first);
  t.appeared = lo + f * (samples[first].time - lo);
  t.latency = t.appeared - shown;
  return t;
}

bool transitionSettled(const std::vector<BrightnessSample>& samples, double shown,
                       const TransitionOptions& options) {
  if (!validate(samples, shown)) return false;
  const std::size_t k = static_cast<std::size_t>(std::max(1, options.settled_samples));
  const std::size_t n = samples.size();
  const std::size_t n_old = countBefore(samples, shown);
  if (n_old == 0 || n - n_old < k) return false;
  const double old_level = median(levels(samples, 0, n_old));
  const std::vector<double> last = levels(samples, n - k, n);
  const double level = median(last);
  const auto [lo, hi] = std::minmax_element(last.begin(), last.end());
  const double distance = std::abs(level - old_level);
  return distance >= options.min_contrast && *hi - *lo <= 0.5 * distance;
}

Result<LatencyStats> latencyStats(std::vector<double> latencies) {
  if (latencies.empty()) return fail(ErrorCode::kInvalidInput, "no latency measured");
  for (double l : latencies) {
    if (!std::isfinite(l)) return fail(ErrorCode::kInvalidInput, "a latency is not finite");
  }
  LatencyStats s;
  const auto [lo, hi] = std::minmax_element(latencies.begin(), latencies.end());
  s.min = *lo;
  s.max = *hi;
  s.spread = s.max - s.min;
  s.count = static_cast<int>(latencies.size());
  s.median = median(std::move(latencies));
  return s;
}

int settleFrames(double latency_s, double refresh_hz, int margin_frames) {
  const double frames = std::max(0.0, latency_s) * std::max(0.0, refresh_hz);
  if (!std::isfinite(frames)) return std::max(0, margin_frames);
  return static_cast<int>(std::ceil(frames - 1e-9)) + std::max(0, margin_frames);
}

}  // namespace procam::sl
