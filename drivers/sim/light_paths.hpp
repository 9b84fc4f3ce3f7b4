#pragma once
// The light a still camera's pixels receive, split by where it comes from: the
// ambient light, and for every sample a projector lights, the framebuffer position
// the light leaves from and the weight of its emission there (albedo * brightness *
// cos / d^2 over the supersamples, [Raskar02] §5.2.4). Traced once while nothing
// moves (Renderer::cameraLightPaths), it lights the camera image for any
// framebuffers with one bilinear lookup per lit sample instead of a ray cast, the
// lens distortion's inversion and a shadow ray per projector: a calibration's
// patterns change only what the projectors show.
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "sim/projector_image.hpp"

namespace procam::sim {

struct LightPaths {
  struct Path {
    float x = 0, y = 0;               // framebuffer position (ProjectorImage::sample)
    cv::Vec3f weight{0.f, 0.f, 0.f};  // BGR radiance per unit of linear emission
    std::uint32_t projector = 0;      // index into SceneState::projectors
  };
  struct Row {
    std::vector<Path> paths;
    std::vector<std::uint32_t> end;  // end[x]: one past pixel x's last path
  };
  // 24 bytes each: 16 million keep a camera's paths under 400 MB (a 1280x960 camera
  // with 4 samples under two projectors is 9.8 million at most).
  static constexpr std::size_t kMaxPaths = 16'000'000;

  cv::Mat ambient;  // CV_32FC3: the radiance with every projector dark
  std::vector<Row> rows;

  std::size_t size() const;
  // One row per ambient row, one end per pixel, ends rising within the row's paths:
  // what light() indexes by.
  bool consistent() const;
  // The radiance (CV_32FC3, BGR) while projector i shows `images[i]` (nullptr:
  // dark); `threads` as RenderOptions::threads.
  cv::Mat light(const std::vector<const ProjectorImage*>& images, int threads = 0) const;
};

}  // namespace procam::sim
