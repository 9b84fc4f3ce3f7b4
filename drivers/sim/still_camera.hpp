#pragma once
// A camera of a scene that does not move filming one frame after another (a pattern
// sequence): its light paths are traced once (light_paths.hpp), and every capture
// lights them with what the projectors show, the image Renderer::renderCamera gives
// to float rounding without a ray cast per frame.
#include <string>

#include "sim/renderer.hpp"

namespace procam::sim {

class StillCamera {
 public:
  // kNotFound for a camera the scene does not have. `scene` must outlive the camera.
  static Result<StillCamera> create(const Scene& scene, SceneState state, std::string camera,
                                    int threads = 0);

  // The camera image while the projectors show `shown` (as Renderer::create takes it).
  Result<cv::Mat> capture(const Framebuffers& shown, const RenderOptions& options = {}) const;

  const std::string& name() const { return camera_; }

 private:
  StillCamera(const Scene& scene, SceneState state, std::string camera, LightPaths paths)
      : scene_(&scene),
        state_(std::move(state)),
        camera_(std::move(camera)),
        paths_(std::move(paths)) {}
  const Scene* scene_;
  SceneState state_;
  std::string camera_;
  LightPaths paths_;
};

}  // namespace procam::sim
