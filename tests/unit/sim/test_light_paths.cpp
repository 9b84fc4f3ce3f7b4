// Light paths traced once for a still camera (light_paths.hpp) light the same
// image as casting every ray again, whatever the projectors show: on scenes with
// lens distortion, a printed board, projector shadows and four overlapping
// projectors, one of them dark.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"

namespace procam::sim {
namespace {

// Framebuffers of uniform noise for every projector but the last, which stays dark.
Framebuffers noiseFrames(const SceneState& state, std::uint64_t seed) {
  Framebuffers frames;
  cv::RNG rng(seed);
  for (std::size_t i = 0; i + 1 < state.projectors.size() || state.projectors.size() == 1; ++i) {
    const auto& p = state.projectors[i];
    cv::Mat f(p.model.height, p.model.width, CV_8UC3);
    rng.fill(f, cv::RNG::UNIFORM, 0, 256);
    frames[p.spec.name] = f;
    if (state.projectors.size() == 1) break;
  }
  return frames;
}

class LightPathsScene : public ::testing::TestWithParam<const char*> {};

TEST_P(LightPathsScene, LightTheImageACastWould) {
  auto scene = resolveScene(GetParam());
  ASSERT_TRUE(scene) << scene.error().message;
  const SceneState state = scene->at(0.0);
  const std::string camera = state.cameras.at(0).spec.name;

  // Traced while the projectors show one set of frames, lit with another.
  auto tracer = Renderer::create(*scene, state, noiseFrames(state, 1));
  ASSERT_TRUE(tracer);
  auto paths = tracer->cameraLightPaths(camera);
  ASSERT_TRUE(paths);
  ASSERT_GT(paths->size(), 0u);

  auto renderer = Renderer::create(*scene, state, noiseFrames(state, 2));
  ASSERT_TRUE(renderer);
  auto cast = renderer->cameraRadiance(camera);
  auto lit = renderer->cameraRadiance(camera, *paths);
  ASSERT_TRUE(cast && lit);
  double peak = 0, worst = 0;
  cv::minMaxLoc(cast->reshape(1), nullptr, &peak);
  const cv::Mat difference = cv::abs(*cast - *lit);
  cv::minMaxLoc(difference.reshape(1), nullptr, &worst);
  // A path keeps its framebuffer position as a float: 2^-24 of 2048 px, 1.2e-4 px,
  // on noise that changes by up to the peak from one pixel to the next, bounds the
  // difference by 1.2e-4 of the peak (a camera's 8-bit step is 3.9e-3 of it).
  EXPECT_GT(peak, 0.0);
  EXPECT_LE(worst, 1.2e-4 * peak) << GetParam();
  std::printf("%s: %zu paths, worst difference %.2e of a peak %.3f\n", GetParam(), paths->size(),
              worst, peak);

  // Paths of another camera's size are refused.
  LightPaths other;
  other.ambient = cv::Mat(3, 4, CV_32FC3, cv::Scalar::all(0));
  other.rows.resize(3);
  auto refused = renderer->cameraRadiance(camera, other);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::kInvalidInput);
  // So are paths whose rows do not index their own paths.
  EXPECT_TRUE(paths->consistent());
  LightPaths broken = *paths;
  broken.rows.back().end.back() = static_cast<std::uint32_t>(broken.rows.back().paths.size() + 1);
  EXPECT_FALSE(broken.consistent());
  auto malformed = renderer->cameraRadiance(camera, broken);
  ASSERT_FALSE(malformed);
  EXPECT_EQ(malformed.error().code, ErrorCode::kInvalidInput);
}

INSTANTIATE_TEST_SUITE_P(Scenes, LightPathsScene,
                         ::testing::Values("corner_stereo", "wall_oblique_board", "object_box",
                                           "tiled_wall"));

}  // namespace
}  // namespace procam::sim
