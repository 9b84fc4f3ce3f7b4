#pragma once
// The one virtual world the mock drivers of a process share: every mock
// device opened on the same scene sees the frames the mock outputs show, on a
// common clock (seconds since the world was first opened).
#include <chrono>
#include <memory>
#include <mutex>
#include <string>

#include "core/error.hpp"
#include "sim/renderer.hpp"
#include "sim/scene.hpp"

namespace procam::sim::mock {

class SimWorld {
 public:
  // The world of a scene (a shipped scene's name or a file), created on first use.
  static Result<std::shared_ptr<SimWorld>> open(const std::string& scene);

  const Scene& scene() const { return scene_; }
  double now() const;

  void show(const std::string& projector, cv::Mat framebuffer);
  Framebuffers shown() const;

  explicit SimWorld(Scene scene) : scene_(std::move(scene)) {}

 private:
  Scene scene_;
  std::chrono::steady_clock::time_point epoch_ = std::chrono::steady_clock::now();
  mutable std::mutex mutex_;
  Framebuffers shown_;
};

}  // namespace procam::sim::mock
