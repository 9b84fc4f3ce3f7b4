#pragma once
// Shows a pattern set on the virtual rig (drivers/sim) and captures it with the
// scene's cameras; scenes are the shipped ones with test-specific edits (smaller
// resolutions, the reference capture conditions' noise, gamma and ambient light).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "sim/renderer.hpp"
#include "sim/scene.hpp"
#include "sim/still_camera.hpp"
#include "structured_light/pattern_set.hpp"

namespace procam::testing {

inline std::string sceneText(const std::string& name) {
  const char* root = std::getenv("PROCAM_SOURCE_DIR");
  std::ifstream in(std::string(root ? root : ".") + "/tests/scenes/" + name + ".toml");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Replaces every occurrence of `from` (which must occur) by `to`.
inline bool edit(std::string& text, const std::string& from, const std::string& to) {
  bool found = false;
  for (std::size_t at = text.find(from); at != std::string::npos;
       at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
    found = true;
  }
  return found;
}

// Scales the device whose "resolution = [W, H]" line is `resolution` by `factor`:
// the resolution and the intrinsics line after it (pixel centres at integers, so
// c' = (c + 0.5) * factor - 0.5).
inline bool scaleDevice(std::string& text, int width, int height, double factor) {
  const std::string res =
      "resolution = [" + std::to_string(width) + ", " + std::to_string(height) + "]";
  const std::size_t at = text.find(res);
  if (at == std::string::npos) return false;
  const std::size_t k = text.find("intrinsics = {", at);
  const std::size_t end = text.find('}', k);
  if (k == std::string::npos || end == std::string::npos) return false;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  if (std::sscanf(text.c_str() + k, "intrinsics = { fx = %lf, fy = %lf, cx = %lf, cy = %lf }", &fx,
                  &fy, &cx, &cy) != 4)
    return false;
  char line[160];
  std::snprintf(line, sizeof line, "intrinsics = { fx = %.6f, fy = %.6f, cx = %.6f, cy = %.6f }",
                fx * factor, fy * factor, (cx + 0.5) * factor - 0.5, (cy + 0.5) * factor - 0.5);
  text.replace(k, end + 1 - k, line);
  text.replace(at, res.size(),
               "resolution = [" + std::to_string(static_cast<int>(width * factor)) + ", " +
                   std::to_string(static_cast<int>(height * factor)) + "]");
  return true;
}

// Median linear radiance over the camera pixels the projector lights, with the
// projector all white and all black.
struct Levels {
  double white = 0, black = 0;
};
inline Levels radianceLevels(const sim::Scene& scene, const std::string& camera) {
  const sim::SceneState state = scene.at(0);
  const auto& p = state.projectors[0].model;
  const std::string proj = state.projectors[0].spec.name;
  Levels l;
  for (int v : {255, 0}) {
    auto r = sim::Renderer::create(scene, state,
                                   {{proj, cv::Mat(p.height, p.width, CV_8UC1, cv::Scalar(v))}});
    auto radiance = r->cameraRadiance(camera);
    auto truth = r->cameraTruth(camera);
    std::vector<float> values;
    for (int y = 0; y < radiance->rows; y += 2)
      for (int x = 0; x < radiance->cols; x += 2)
        if (truth->lit[0].at<std::uint8_t>(y, x))
          values.push_back(radiance->at<cv::Vec3f>(y, x)[1]);
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    (v == 255 ? l.white : l.black) = values.empty() ? 0 : values[values.size() / 2];
  }
  return l;
}

// The reference lighting: ambient 10% of the white level and white at 75% of full
// scale, on the median lit pixel of `camera`. The scene's ambient line must read
// "ambient = <ambient_text>"; "exposure = E" is added after `exposure_marker`, a
// line of every camera block.
inline std::string withIssueLighting(std::string text, const std::string& camera,
                                     const std::string& ambient_text,
                                     const std::string& exposure_marker) {
  const double ambient = std::stod(ambient_text);
  auto scene = sim::Scene::parse(text, "lighting probe", {});
  if (!scene) return text;
  const Levels l = radianceLevels(*scene, camera);
  const double projector = l.white - l.black;
  const double k = projector / (9.0 * l.black);  // k * black = 0.1 * (k * black + projector)
  const double exposure = 0.75 / (k * l.black + projector);
  edit(text, "ambient = " + ambient_text, "ambient = " + std::to_string(ambient * k));
  edit(text, exposure_marker, exposure_marker + "\nexposure = " + std::to_string(exposure));
  return text;
}

// captures[camera][frame] for the named cameras (all when empty).
inline Result<std::map<std::string, std::vector<cv::Mat>>> capture(
    const sim::Scene& scene, const sl::PatternSet& set, std::uint64_t seed,
    const std::vector<std::string>& cameras = {}) {
  const sim::SceneState state = scene.at(0);
  std::vector<sim::StillCamera> filming;
  for (const auto& cam : state.cameras) {
    if (!cameras.empty() &&
        std::find(cameras.begin(), cameras.end(), cam.spec.name) == cameras.end())
      continue;
    auto still = sim::StillCamera::create(scene, state, cam.spec.name);
    if (!still) return tl::unexpected(still.error());
    filming.push_back(std::move(*still));
  }
  std::map<std::string, std::vector<cv::Mat>> out;
  for (std::size_t i = 0; i < set.frames.size(); ++i) {
    const sim::Framebuffers shown = {{state.projectors[0].spec.name, sl::renderFrame(set, i)}};
    for (const sim::StillCamera& cam : filming) {
      auto image = cam.capture(shown, {.noise = true, .seed = seed * 1000 + i});
      if (!image) return tl::unexpected(image.error());
      out[cam.name()].push_back(*image);
    }
  }
  return out;
}

}  // namespace procam::testing
