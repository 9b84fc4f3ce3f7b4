// object_box: the box casts a projector shadow on the table exactly where the
// geometry says. Every camera pixel that sees the table is predicted from its four
// supersample rays (stratum centres, SCENE-FORMAT.md) with an independent slab
// test against the box, and must match the rendered code within 1 DN.
// (The scene's camera has no lens blur, so each pixel is exactly its samples' mean.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "unit/sim/rotated_grid.hpp"

namespace procam::sim {
namespace {

using testing::kSampleOffsets;

// Axis-aligned box [lo, hi]: does the segment p + s (q - p), s in (0, 1), enter it?
bool segmentHitsBox(const Vec3& p, const Vec3& q, const Vec3& lo, const Vec3& hi) {
  double s0 = 1e-9, s1 = 1 - 1e-9;
  const Vec3 d = q - p;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-15) {
      if (p[a] < lo[a] || p[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - p[a]) / d[a], tb = (hi[a] - p[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    s0 = std::max(s0, ta);
    s1 = std::min(s1, tb);
    if (s0 > s1) return false;
  }
  return true;
}

TEST(SimShadow, BoxShadowOnTableMatchesGeometry) {
  auto scene = resolveScene("object_box");
  ASSERT_TRUE(scene) << scene.error().message;
  const SceneState state = scene->at(0.0);
  const ProjectorState& proj = state.projectors.at(0);
  const CameraState& cam = state.cameras.at(0);
  ASSERT_EQ(cam.spec.supersamples, 4);
  ASSERT_EQ(cam.spec.response_gamma, 1.0);
  ASSERT_EQ(cam.spec.psf_sigma_px, 0.0);

  // The scene file's numbers (object_box.toml).
  const double table_z = 0.75, albedo = 0.7, ambient = scene->ambientRgb().x();
  const Vec3 box_lo(-0.05, 1.4, 0.75), box_hi(0.25, 1.6, 1.0);
  const Vec3 c_proj = proj.model.pose.center();
  const Vec3 c_cam = cam.model.pose.center();
  const double max_dn = cam.spec.maxDn();
  const double margin = 3 * proj.spec.blur_sigma_px + 2;  // away from the dark frame edge

  const cv::Mat white(proj.model.height, proj.model.width, CV_8UC1, cv::Scalar(255));
  auto renderer = Renderer::create(*scene, state, {{"proj", white}});
  ASSERT_TRUE(renderer);
  RenderOptions options;
  options.noise = false;
  auto image = renderer->renderCamera("cam", options);
  ASSERT_TRUE(image);

  int full_shadow = 0, partial = 0, lit = 0;
  double worst = 0;
  // Every second row and column keeps the test fast; the shadow edge still crosses
  // hundreds of checked pixels.
  for (int y = 0; y < cam.model.height; y += 2) {
    for (int x = 0; x < cam.model.width; x += 2) {
      double radiance = 0;
      int shadowed = 0;
      bool usable = true;
      for (int k = 0; k < 4 && usable; ++k) {
        const Vec2 sample = Vec2(x, y) + kSampleOffsets[k];
        auto ray = cam.model.backproject(sample);
        ASSERT_TRUE(ray);
        const double s = (table_z - ray->origin.z()) / ray->dir.z();
        const Vec3 X = ray->at(s);
        const bool on_table = s > 0 && std::abs(X.x()) <= 0.8 && std::abs(X.y() - 1.5) <= 0.45;
        const auto u = proj.model.project(X);
        usable = on_table && !segmentHitsBox(c_cam, X, box_lo, box_hi) && u && u->x() > margin &&
                 u->x() < proj.model.width - 1 - margin && u->y() > margin &&
                 u->y() < proj.model.height - 1 - margin;
        if (!usable) break;
        const bool dark = segmentHitsBox(c_proj, X, box_lo, box_hi);
        shadowed += dark;
        const Vec3 to_proj = c_proj - X;
        const double d = to_proj.norm();
        const double cos_theta = to_proj.z() / d;  // table normal +Z
        radiance += albedo * (ambient + (dark ? 0.0 : proj.spec.brightness * cos_theta / (d * d)));
      }
      if (!usable) continue;
      const double expected = std::round(max_dn * std::min(1.0, radiance / 4));
      const double got = image->at<std::uint8_t>(y, x);
      worst = std::max(worst, std::abs(got - expected));
      ASSERT_LE(std::abs(got - expected), 1.0)
          << "pixel (" << x << ", " << y << ") with " << shadowed << "/4 samples in shadow";
      if (shadowed == 4)
        ++full_shadow;
      else if (shadowed > 0)
        ++partial;
      else
        ++lit;
    }
  }
  std::printf("table pixels: %d in shadow, %d on the shadow edge, %d lit; worst |diff| %.0f DN\n",
              full_shadow, partial, lit, worst);
  // The test must actually look at a shadow, its edge and lit table.
  EXPECT_GT(full_shadow, 1000);
  EXPECT_GT(partial, 20);
  EXPECT_GT(lit, 10000);
}

}  // namespace
}  // namespace procam::sim
