#include "frame_pacing.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace procam::daemon {

void SensorClock::add(uint64_t arrival_ns, uint64_t timestamp_ns) {
  offsets_.push_back(static_cast<int64_t>(arrival_ns) - static_cast<int64_t>(timestamp_ns));
  if (offsets_.size() > kWindow) offsets_.pop_front();
}

std::optional<int64_t> SensorClock::offsetNs() const {
  if (offsets_.empty()) return std::nullopt;
  return *std::min_element(offsets_.begin(), offsets_.end());
}

std::optional<double> SensorClock::sensorSeconds(uint64_t monotonic_ns) const {
  const auto offset = offsetNs();
  if (!offset) return std::nullopt;
  return static_cast<double>(static_cast<int64_t>(monotonic_ns) - *offset) * 1e-9;
}

void DrawBudget::add(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return;
  recent_.push_back(std::min(seconds, kMax));
  if (recent_.size() > kWindow) recent_.pop_front();
}

double DrawBudget::budget() const {
  if (recent_.empty()) return kInitial;
  std::vector<double> sorted(recent_.begin(), recent_.end());
  const auto k = static_cast<std::ptrdiff_t>(kQuantile * static_cast<double>(sorted.size() - 1));
  std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
  return sorted[static_cast<std::size_t>(k)] + kMargin;
}

uint64_t presentTarget(uint64_t now_ns, double budget_s, uint64_t period_ns,
                       uint64_t last_vblank_ns) {
  const uint64_t ready =
      now_ns + static_cast<uint64_t>(std::llround(std::max(0.0, budget_s) * 1e9));
  if (period_ns == 0 || last_vblank_ns == 0) return ready;
  if (ready <= last_vblank_ns) return last_vblank_ns;
  const uint64_t periods = (ready - last_vblank_ns + period_ns - 1) / period_ns;
  return last_vblank_ns + periods * period_ns;
}

}  // namespace procam::daemon
