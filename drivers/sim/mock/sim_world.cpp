#include "sim_world.hpp"

#include <algorithm>
#include <map>

#include "sim/scene_library.hpp"

namespace procam::sim::mock {

namespace {
// Slack over the largest latency: a capture reads the clock before it looks up
// the frames, and a show may come in between.
constexpr double kHistorySlackS = 0.25;
}  // namespace

Result<std::shared_ptr<SimWorld>> SimWorld::open(const std::string& scene) {
  static std::mutex registry_mutex;
  static std::map<std::string, std::weak_ptr<SimWorld>> registry;
  std::lock_guard lock(registry_mutex);
  if (auto existing = registry[scene].lock()) return existing;
  auto loaded = resolveScene(scene);
  if (!loaded) return tl::unexpected(loaded.error());
  auto world = std::make_shared<SimWorld>(std::move(*loaded));
  registry[scene] = world;
  return world;
}

SimWorld::SimWorld(Scene scene) : scene_(std::move(scene)) {
  double latency = 0;
  for (const auto& c : scene_.cameras()) latency = std::max(latency, c.latency_s);
  keep_s_ = latency > 0 ? latency + kHistorySlackS : 0;
}

double SimWorld::now() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - epoch_).count();
}

uint64_t SimWorld::monotonicNs(double world_time) const {
  const auto at = epoch_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                               std::chrono::duration<double>(world_time));
  return static_cast<uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(at.time_since_epoch()).count());
}

double SimWorld::worldTime(uint64_t monotonic_ns) const {
  const auto at = std::chrono::steady_clock::time_point(
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::nanoseconds(monotonic_ns)));
  return std::chrono::duration<double>(at - epoch_).count();
}

double SimWorld::show(const std::string& projector, cv::Mat framebuffer, std::optional<double> at) {
  const double t = now();
  std::lock_guard lock(mutex_);
  History& h = history_[projector];
  double on = std::max(t, at.value_or(t));
  if (!h.frames.empty()) on = std::max(on, h.frames.back().time);
  h.frames.push_back({on, std::move(framebuffer)});
  ++shows_;
  // Keep the frame that was on at t - keep_s_ (the one before the first younger
  // than that) and those to come, and no more than kMaxKeptFrames.
  while (h.frames.size() > 1 &&
         (h.frames[1].time <= t - keep_s_ || h.frames.size() > kMaxKeptFrames)) {
    h.frames.pop_front();
    h.trimmed = true;
  }
  return on;
}

std::uint64_t SimWorld::showCount() const {
  const double t = now();
  std::lock_guard lock(mutex_);
  std::uint64_t to_come = 0;  // frames asked to go on later
  for (const auto& [name, h] : history_) {
    for (auto it = h.frames.rbegin(); it != h.frames.rend() && it->time > t; ++it) ++to_come;
  }
  return shows_ - to_come;
}

Framebuffers SimWorld::shown() const {
  return shownAt(now());
}

Framebuffers SimWorld::shownAt(double t) const {
  std::lock_guard lock(mutex_);
  Framebuffers out;
  for (const auto& [name, h] : history_) {
    // The last frame shown at or before t.
    auto after = std::upper_bound(h.frames.begin(), h.frames.end(), t,
                                  [](double time, const Shown& s) { return time < s.time; });
    if (after != h.frames.begin()) {
      out[name] = std::prev(after)->frame;
    } else if (h.trimmed) {
      out[name] = h.frames.front().frame;  // before the kept history
    }
  }
  return out;
}

}  // namespace procam::sim::mock
