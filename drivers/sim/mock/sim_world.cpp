#include "sim_world.hpp"

#include <map>

#include "sim/scene_library.hpp"

namespace procam::sim::mock {

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

double SimWorld::now() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - epoch_).count();
}

void SimWorld::show(const std::string& projector, cv::Mat framebuffer) {
  std::lock_guard lock(mutex_);
  shown_[projector] = std::move(framebuffer);
}

Framebuffers SimWorld::shown() const {
  std::lock_guard lock(mutex_);
  return shown_;
}

}  // namespace procam::sim::mock
