// Bit depth, response gamma, noise statistics and colour of the camera model, on a
// flat wall whose light is known in closed form (sim_test_util.hpp): radiance =
// albedo * (ambient + brightness * v^gamma_p * cos / d^2).
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>

#include "sim/renderer.hpp"
#include "sim_test_util.hpp"
#include "unit/sim/rotated_grid.hpp"

namespace procam::sim {
namespace {

using testing::flatWallScene;

// Framebuffer of 4 x 2 flat patches (80 x 120 px each) with increasing levels.
constexpr int kPatchW = 80, kPatchH = 120;
int patchLevel(int px, int py) {
  return (py / kPatchH * 4 + px / kPatchW) * 255 / 7;
}

cv::Mat patches() {
  cv::Mat fb(240, 320, CV_8UC1);
  for (int y = 0; y < fb.rows; ++y)
    for (int x = 0; x < fb.cols; ++x) fb.at<std::uint8_t>(y, x) = patchLevel(x, y);
  return fb;
}

using testing::kSampleOffsets;

// Exact radiance of one camera pixel (mean over its 2 x 2 samples),
// or -1 when a sample's framebuffer neighbourhood is not one flat patch.
struct Analytic {
  const Scene& scene;
  const SceneState& state;
  int patch = -1;

  double pixelRadiance(int x, int y) {
    const ProjectorState& p = state.projectors.at(0);
    const CameraState& c = state.cameras.at(0);
    double sum = 0;
    patch = -1;
    for (int k = 0; k < 4; ++k) {
      auto ray = c.model.backproject(Vec2(x, y) + kSampleOffsets[k]);
      const Vec3 X = ray->at((2.0 - ray->origin.y()) / ray->dir.y());  // wall y = 2
      const auto u = p.model.project(X);
      if (!u) return -1;
      const int px = static_cast<int>(std::lround(u->x())),
                py = static_cast<int>(std::lround(u->y()));
      // Two framebuffer pixels of margin: bilinear neighbours share the level.
      if (px % kPatchW < 2 || px % kPatchW > kPatchW - 3 || py % kPatchH < 2 ||
          py % kPatchH > kPatchH - 3 || px < 0 || py < 0 || px >= 320 || py >= 240)
        return -1;
      const int id = py / kPatchH * 4 + px / kPatchW;
      if (patch >= 0 && id != patch) return -1;
      patch = id;
      const Vec3 to_p = p.model.pose.center() - X;
      const double d = to_p.norm();
      const double level = std::pow(patchLevel(px, py) / 255.0, p.spec.gamma);
      const double cos_theta = -to_p.y() / d;  // wall normal (0, -1, 0)
      sum += 0.7 * (scene.ambientRgb().x() + p.spec.brightness * level * cos_theta / (d * d));
    }
    return sum / 4;
  }
};

Result<cv::Mat> render(const Scene& scene, bool noise, std::uint64_t seed = 7, int threads = 0) {
  auto r = Renderer::create(scene, scene.at(0), {{"proj", patches()}});
  if (!r) return tl::unexpected(r.error());
  RenderOptions o;
  o.noise = noise;
  o.seed = seed;
  o.threads = threads;
  return r->renderCamera("cam", o);
}

double code(const cv::Mat& m, int x, int y) {
  return m.depth() == CV_8U ? m.at<std::uint8_t>(y, x) : m.at<std::uint16_t>(y, x);
}

class SimResponse : public ::testing::TestWithParam<std::tuple<int, double>> {};

// Noise off: every code is maxDN * (exposure * gain * radiance)^(1/gamma_c), rounded.
TEST_P(SimResponse, NoiseFreeCodesFollowBitDepthAndGamma) {
  const auto [bits, gamma] = GetParam();
  auto scene = Scene::parse(flatWallScene("bit_depth = " + std::to_string(bits) +
                                          "\nresponse_gamma = " + std::to_string(gamma) +
                                          "\nexposure = 1.2\ngain = 1.1\n"),
                            "flat.toml", {});
  ASSERT_TRUE(scene) << scene.error().message;
  auto image = render(*scene, false);
  ASSERT_TRUE(image);
  ASSERT_EQ(image->type(), bits <= 8 ? CV_8UC1 : CV_16UC1);
  const SceneState state = scene->at(0);
  Analytic a{*scene, state};
  const double max_dn = (1 << bits) - 1;
  int checked = 0;
  for (int y = 0; y < image->rows; ++y) {
    for (int x = 0; x < image->cols; ++x) {
      const double r = a.pixelRadiance(x, y);
      if (r < 0) continue;
      const double expected = max_dn * std::pow(std::min(1.0, 1.2 * 1.1 * r), 1.0 / gamma);
      // Rounding to the nearest code, plus float accumulation in the renderer.
      ASSERT_NEAR(code(*image, x, y), expected, 0.5 + 2e-5 * max_dn) << x << "," << y;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20000);
}

INSTANTIATE_TEST_SUITE_P(BitsAndGamma, SimResponse,
                         ::testing::Combine(::testing::Values(8, 10, 12, 16),
                                            ::testing::Values(1.0, 2.2)));

// Noise on (linear camera): per flat patch the mean code and the standard deviation
// about the exact per-pixel mean match the model within 5% (the simulator's noise
// fidelity bound):
// sigma^2 = gain * mu / (electrons per DN) + read^2 + 1/12 (quantisation).
TEST(SimPhotometry, NoiseMeanAndSigmaMatchTheScene) {
  const double gain = 1.5, full_well = 20000, read = 3.0;
  auto scene = Scene::parse(flatWallScene("bit_depth = 12\ngain = 1.5\nfull_well_e = 20000.0\n"
                                          "read_noise_dn = 3.0\n"),
                            "flat.toml", {});
  ASSERT_TRUE(scene) << scene.error().message;
  auto image = render(*scene, true);
  ASSERT_TRUE(image);
  const SceneState state = scene->at(0);
  Analytic a{*scene, state};
  const double max_dn = 4095, e_per_dn = full_well / max_dn;
  struct Acc {
    double n = 0, mean_expected = 0, mean_code = 0, sq_residual = 0;
  };
  std::vector<Acc> acc(8);
  for (int y = 0; y < image->rows; ++y) {
    for (int x = 0; x < image->cols; ++x) {
      const double r = a.pixelRadiance(x, y);
      if (r < 0) continue;
      const double mu = max_dn * gain * r;
      const double c = code(*image, x, y);
      Acc& p = acc[static_cast<std::size_t>(a.patch)];
      p.n += 1;
      p.mean_expected += mu;
      p.mean_code += c;
      p.sq_residual += (c - mu) * (c - mu);
    }
  }
  int patches_checked = 0;
  for (const Acc& p : acc) {
    ASSERT_GT(p.n, 1500);
    const double mu = p.mean_expected / p.n;
    const double sigma_model = std::sqrt(gain * mu / e_per_dn + read * read + 1.0 / 12);
    const double sigma = std::sqrt(p.sq_residual / p.n);
    EXPECT_NEAR(p.mean_code / p.n, mu, 0.05 * mu + 1e-9) << "patch mean";
    EXPECT_NEAR(sigma, sigma_model, 0.05 * sigma_model) << "patch at mean " << mu;
    ++patches_checked;
  }
  EXPECT_EQ(patches_checked, 8);
}

TEST(SimPhotometry, SaturatesAtTheFullScaleOfTheBitDepth) {
  for (const int bits : {8, 10, 14, 16}) {
    for (const int channels : {1, 3}) {
      auto scene = Scene::parse(
          flatWallScene("bit_depth = " + std::to_string(bits) +
                        "\nchannels = " + std::to_string(channels) + "\nexposure = 50.0\n"),
          "flat.toml", {});
      ASSERT_TRUE(scene);
      auto r = Renderer::create(*scene, scene->at(0), {{"proj", cv::Mat(240, 320, CV_8UC1, 255)}});
      ASSERT_TRUE(r);
      RenderOptions o;
      o.noise = false;
      auto image = r->renderCamera("cam", o);
      ASSERT_TRUE(image);
      EXPECT_EQ(image->depth(), bits <= 8 ? CV_8U : CV_16U);
      EXPECT_EQ(image->channels(), channels);
      double lo = 0, hi = 0;
      cv::minMaxLoc(image->reshape(1), &lo, &hi);
      EXPECT_EQ(hi, (1 << bits) - 1) << bits << " bits";
    }
  }
}

// A red framebuffer lights only the red channel of a colour camera; the others see
// the ambient light alone.
TEST(SimPhotometry, ColourChannelsStaySeparate) {
  auto scene = Scene::parse(flatWallScene("channels = 3\nbit_depth = 12\n"), "flat.toml", {});
  ASSERT_TRUE(scene);
  auto r = Renderer::create(*scene, scene->at(0),
                            {{"proj", cv::Mat(240, 320, CV_8UC3, cv::Scalar(0, 0, 255))}});
  ASSERT_TRUE(r);
  RenderOptions o;
  o.noise = false;
  auto image = r->renderCamera("cam", o);
  ASSERT_TRUE(image);
  const cv::Vec3w centre = image->at<cv::Vec3w>(90, 80);  // lit by the projector
  const double ambient_code = std::round(4095 * 0.7 * 0.05);
  EXPECT_EQ(centre[0], ambient_code);
  EXPECT_EQ(centre[1], ambient_code);
  EXPECT_GT(centre[2], 10 * ambient_code);
}

// The viewer's perceived image is the noise-free radiance itself.
TEST(SimPhotometry, ViewerImageIsTheAnalyticRadiance) {
  auto scene = Scene::parse(flatWallScene(""), "flat.toml", {});
  ASSERT_TRUE(scene);
  const SceneState state = scene->at(0);
  auto r = Renderer::create(*scene, state, {{"proj", patches()}});
  ASSERT_TRUE(r);
  // A viewer standing where the camera is sees what the camera's radiance is.
  geom::CameraModel view = state.cameras.at(0).model;
  const cv::Mat seen = r->renderView(view, 4);
  ASSERT_EQ(seen.type(), CV_32FC3);
  Analytic a{*scene, state};
  int checked = 0;
  for (int y = 0; y < seen.rows; y += 7) {
    for (int x = 0; x < seen.cols; x += 7) {
      const double expected = a.pixelRadiance(x, y);
      if (expected < 0) continue;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(seen.at<cv::Vec3f>(y, x)[c], expected, 1e-5);
      ++checked;
    }
  }
  EXPECT_GT(checked, 200);
}

TEST(SimPhotometry, NoiseIsDeterministicAndIndependentOfThreads) {
  auto scene =
      Scene::parse(flatWallScene("read_noise_dn = 2.0\nfull_well_e = 5000.0\n"), "flat.toml", {});
  ASSERT_TRUE(scene);
  auto one = render(*scene, true, 11, 1);
  auto all = render(*scene, true, 11, 0);
  auto other_seed = render(*scene, true, 12, 0);
  ASSERT_TRUE(one && all && other_seed);
  EXPECT_EQ(cv::norm(*one, *all, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(*one, *other_seed, cv::NORM_L1), 0.0);
}

}  // namespace
}  // namespace procam::sim
