#include "sim/still_camera.hpp"

namespace procam::sim {

Result<StillCamera> StillCamera::create(const Scene& scene, SceneState state, std::string camera,
                                        int threads) {
  auto tracer = Renderer::create(scene, state, {});
  if (!tracer) return tl::unexpected(tracer.error());
  auto paths = tracer->cameraLightPaths(camera, threads);
  if (!paths) return tl::unexpected(paths.error());
  return StillCamera(scene, std::move(state), std::move(camera), std::move(*paths));
}

Result<cv::Mat> StillCamera::capture(const Framebuffers& shown,
                                     const RenderOptions& options) const {
  auto renderer = Renderer::create(*scene_, state_, shown);
  if (!renderer) return tl::unexpected(renderer.error());
  auto radiance = renderer->cameraRadiance(camera_, paths_, options.threads);
  if (!radiance) return tl::unexpected(radiance.error());
  const CameraState* cam = renderer->state().camera(camera_);
  return Renderer::cameraImage(cam->spec, *radiance, options);
}

}  // namespace procam::sim
