#include "reading_stats.hpp"

namespace procam::daemon {

bool ReadingStats::add(uint64_t timestamp_ns, Clock::time_point arrived) {
  if (count_ > 0 && timestamp_ns == last_ns_) return false;
  ++count_;
  last_ns_ = timestamp_ns;
  arrivals_.push_back(arrived);
  while (!arrivals_.empty() && arrived - arrivals_.front() > kWindow) arrivals_.pop_front();
  return true;
}

double ReadingStats::rateHz(Clock::time_point now) const {
  // Arrivals older than the window no longer count: a device that stopped reads 0.
  auto first = arrivals_.begin();
  while (first != arrivals_.end() && now - *first > kWindow) ++first;
  const auto n = std::distance(first, arrivals_.end());
  if (n < 2) return 0;
  const double span = std::chrono::duration<double>(arrivals_.back() - *first).count();
  return span > 0 ? static_cast<double>(n - 1) / span : 0;
}

nlohmann::json ReadingStats::toJson(const char* count_key) const {
  return {{count_key, count_},
          {"rate_hz", rateHz()},
          {"last_timestamp", static_cast<double>(last_ns_) * 1e-9}};
}

}  // namespace procam::daemon
