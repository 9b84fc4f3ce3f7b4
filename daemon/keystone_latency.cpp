#include "keystone_latency.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace procam::daemon {

void KeystoneLatency::add(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return;
  ++frames_;
  recent_.push_back(seconds);
  if (recent_.size() > kWindow) recent_.pop_front();
}

double KeystoneLatency::median() const {
  if (recent_.empty()) return 0;
  std::vector<double> v(recent_.begin(), recent_.end());
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

nlohmann::json KeystoneLatency::toJson() const {
  if (recent_.empty()) return nullptr;
  std::vector<double> sorted(recent_.begin(), recent_.end());
  std::sort(sorted.begin(), sorted.end());
  // Element floor(q n): at 0.5 the same median as median(), which the prediction's lead is.
  const auto at = [&](double q) {
    const auto i = static_cast<std::size_t>(q * static_cast<double>(sorted.size()));
    return 1e3 * sorted[std::min(i, sorted.size() - 1)];
  };
  return {{"frames", frames_},
          {"last_ms", 1e3 * recent_.back()},
          {"median_ms", at(0.5)},
          {"p95_ms", at(0.95)},
          {"max_ms", 1e3 * sorted.back()}};
}

}  // namespace procam::daemon
