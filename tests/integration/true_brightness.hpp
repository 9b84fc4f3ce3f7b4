#pragma once
// A projector's TRUE white across its frame on the virtual rig's surfaces: its
// brightness cos θ / d² times the surface's albedo at each node of a brightness map
// (what a linear camera measures up to one factor; the rig's point source, [Raskar02]
// §5.2.4), for tests that hand procam-render a known rig.
#include <algorithm>

#include "blend/brightness_map.hpp"
#include "render/viewer_view.hpp"
#include "rig/rig_model.hpp"
#include "sim/scene.hpp"

namespace procam::itest {

inline blend::BrightnessMap trueBrightness(const sim::Scene& scene, const sim::SceneState& state,
                                           std::size_t projector, int step = 32) {
  const auto& spec = state.projectors[projector].spec;
  const geom::CameraModel& m = state.projectors[projector].model;
  blend::BrightnessMap map;
  map.step = step;
  map.width = spec.width;
  map.height = spec.height;
  const int cols = blend::brightnessNodes(map.width, step);
  const int rows = blend::brightnessNodes(map.height, step);
  map.white = cv::Mat(rows, cols, CV_32FC1, cv::Scalar(1e-6));
  auto rays = render::pixelRays(m.projectionMatrix());
  if (!rays) return map;
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      const geom::Ray ray = rays->through(i * step, j * step);
      const auto hit = scene.world().intersect(ray);
      if (!hit) continue;
      const Vec3 to_lamp = m.pose.center() - hit->hit.point;
      const double d = to_lamp.norm();
      const double cos_incidence = std::max(0.0, hit->hit.normal.dot(to_lamp) / d);
      const double albedo = scene.world().surfaces()[hit->surface].albedo_rgb.mean();
      map.white.at<float>(j, i) =
          static_cast<float>(std::max(1e-6, spec.brightness * cos_incidence / (d * d) * albedo));
    }
  }
  return map;
}

// Each projector of `rig` (the scene's true rig) with its true response and brightness
// across its frame as its photometric record: black 0, white its brightness, what a
// linear camera ("truth") would measure.
inline void addTruePhotometry(const sim::Scene& scene, const sim::SceneState& state,
                              rig::RigModel& rig) {
  for (auto& p : rig.projectors) {
    for (std::size_t i = 0; i < state.projectors.size(); ++i) {
      const auto& s = state.projectors[i];
      if (s.spec.name != p.name) continue;
      p.photometric = {{"response_gamma", s.spec.gamma},
                       {"black", 0.0},
                       {"white", s.spec.brightness},
                       {"brightness", blend::brightnessToJson(trueBrightness(scene, state, i))},
                       {"camera", "truth"}};
    }
  }
}

}  // namespace procam::itest
