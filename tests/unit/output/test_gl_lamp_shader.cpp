// Shader-lamp frames shaded by the GLES program against lamps::lampFrame (the CPU
// reference, doubles) on the same views, weights and look: the vase of object_vase lit by
// two projectors, textured, under a virtual light, with a highlight for a viewer. The GPU
// evaluates the same formula in 32-bit floats, so a code value may round the other way
// where the exact value lies within ~1e-4 of a half code: at most 1 code value apart, and
// on a small share of the pixels.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "egl/egl_context.hpp"
#include "gl/gl_lamp_shader.hpp"
#include "integration/object_meshes.hpp"
#include "shader_lamps/lamp_weights.hpp"
#include "unit/shader_lamps/lamp_rig.hpp"

namespace procam::output::gl {
namespace {

geom::CameraModel projectorAt(const Vec3& at) {
  return lamps::test::projectorAt(at, Vec3(0, 1.5, 0.9), 640, 360, 1150);
}

struct Scene {
  std::vector<geom::CameraModel> models;
  std::optional<lamps::ObjectModel> object;
  std::vector<lamps::LampView> views;
  lamps::LampWeights weights;
  std::vector<lamps::LampFrameInput> inputs;
  lamps::Material look;
  double white = 0;
};

const Scene& scene() {
  static const Scene s = [] {
    Scene s;
    const itest::ObjectMesh vase =
        itest::vaseMesh(Vec3(0, 1.5, 0.85), 0.1, Vec3(0, 1.5, 0.93), 0.045, 0.1, 96);
    s.object = *lamps::ObjectModel::build(vase.mesh, vase.uv);
    s.models = {projectorAt(Vec3(-0.7, 0.5, 1.6)), projectorAt(Vec3(0.7, 0.5, 1.6))};
    for (const auto& m : s.models) s.views.push_back(*lamps::castLampView(m, *s.object));
    std::vector<lamps::Lamp> set;
    for (std::size_t i = 0; i < s.models.size(); ++i)
      set.push_back({&s.models[i], &s.views[i], true});
    s.weights = *lamps::lampWeights(set);
    for (std::size_t i = 0; i < s.models.size(); ++i)
      s.inputs.push_back({&s.views[i], &s.weights.weight[i], {2.0 + 0.4 * i, Vec3(310, 295, 270)}});
    s.look.texture = cv::Mat(128, 256, CV_32FC3);  // not square: rows and columns told apart
    cv::RNG rng(7);
    rng.fill(s.look.texture, cv::RNG::UNIFORM, cv::Scalar::all(0.05), cv::Scalar::all(1.0));
    cv::GaussianBlur(s.look.texture, s.look.texture, cv::Size(0, 0), 2);
    s.look.albedo_rgb = Vec3(0.95, 0.85, 0.7);
    s.look.light_dir = Vec3(0.3, -0.6, 0.75);
    s.look.ambient = 0.25;
    s.look.specular_rgb = Vec3(0.4, 0.4, 0.35);
    s.look.shininess = 40;
    s.white = *lamps::lampWhiteLevel(s.inputs);
    return s;
  }();
  return s;
}

class ShaderLampGles : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto ctx = egl::EglContext::surfaceless();
    ASSERT_TRUE(ctx) << ctx.error().message;
    ctx_ = std::move(*ctx);
    std::printf("GL renderer: %s\n", ctx_->renderer().c_str());
  }
  static void TearDownTestSuite() { ctx_.reset(); }
  static std::unique_ptr<egl::EglContext> ctx_;
};
std::unique_ptr<egl::EglContext> ShaderLampGles::ctx_;

struct Agreement {
  double largest = 0;
  long differing = 0, lit = 0;
};

Agreement compare(const cv::Mat& gpu, const cv::Mat& cpu, const cv::Mat& weight) {
  Agreement a;
  cv::Mat diff;
  cv::absdiff(gpu, cpu, diff);
  a.largest = cv::norm(diff, cv::NORM_INF);
  for (int y = 0; y < diff.rows; ++y) {
    for (int x = 0; x < diff.cols; ++x) {
      if (weight.at<float>(y, x) > 0) ++a.lit;
      const cv::Vec3b d = diff.at<cv::Vec3b>(y, x);
      a.differing += (d[0] | d[1] | d[2]) != 0;
    }
  }
  return a;
}

TEST_F(ShaderLampGles, FramesMatchTheCpuReferenceForEveryProjectorAndEye) {
  const Scene& s = scene();
  auto shader = GlLampShader::create();
  ASSERT_TRUE(shader) << shader.error().message;
  ASSERT_TRUE((*shader)->setMaterial(s.look));
  const std::optional<Vec3> eyes[] = {std::nullopt, Vec3(0, 0.3, 1.4), Vec3(0.5, 0.6, 1.2)};
  cv::Mat previous;
  for (std::size_t i = 0; i < s.inputs.size(); ++i) {
    ASSERT_TRUE((*shader)->setView(s.inputs[i]));
    for (const auto& eye : eyes) {
      const cv::Mat cpu = *lamps::lampFrame(s.inputs[i], s.look, s.white, eye);
      ASSERT_TRUE((*shader)->shade(s.white, eye));
      cv::Mat gpu;
      ASSERT_TRUE((*shader)->readFrame(gpu));
      ASSERT_EQ(gpu.size(), cpu.size());
      ASSERT_EQ(gpu.type(), CV_8UC3);
      const Agreement a = compare(gpu, cpu, s.weights.weight[i]);
      std::printf("projector %zu, %s: largest difference %.0f, %ld of %ld lit pixels differ\n", i,
                  eye ? "eye" : "no eye", a.largest, a.differing, a.lit);
      // The object covers a good part of each frame: the comparison is not of black.
      EXPECT_GT(a.lit, 10000);
      EXPECT_LE(a.largest, 1.0);
      EXPECT_LE(a.differing, a.lit / 200);
      // Each eye moves the highlight: the frames compared are not all the same frame.
      if (!previous.empty()) {
        EXPECT_GT(cv::norm(cpu, previous, cv::NORM_L1), 1e4);
      }
      previous = cpu;
    }
  }
}

TEST_F(ShaderLampGles, AnUntexturedUnlitLookIsTheWeightedCorrectionAlone) {
  const Scene& s = scene();
  auto shader = GlLampShader::create();
  ASSERT_TRUE(shader);
  lamps::Material plain;
  plain.albedo_rgb = Vec3(0.8, 0.5, 0.2);
  ASSERT_TRUE((*shader)->setMaterial(plain));
  ASSERT_TRUE((*shader)->setView(s.inputs[1]));
  ASSERT_TRUE(
      (*shader)->shade(s.white, Vec3(0, 0.3, 1.4)));  // no specular: the eye changes nothing
  cv::Mat gpu;
  ASSERT_TRUE((*shader)->readFrame(gpu));
  const cv::Mat cpu = *lamps::lampFrame(s.inputs[1], plain, s.white, std::nullopt);
  const Agreement a = compare(gpu, cpu, s.weights.weight[1]);
  EXPECT_LE(a.largest, 1.0);
  EXPECT_LE(a.differing, a.lit / 200);
}

TEST_F(ShaderLampGles, BadInputIsRefused) {
  const Scene& s = scene();
  auto shader = GlLampShader::create();
  ASSERT_TRUE(shader);
  EXPECT_EQ((*shader)->shade(1, std::nullopt).error().code, ErrorCode::kInvalidInput);
  cv::Mat frame;
  EXPECT_EQ((*shader)->readFrame(frame).error().code, ErrorCode::kInvalidInput);
  lamps::LampFrameInput no_weight{&s.views[0], nullptr, {}};
  EXPECT_EQ((*shader)->setView(no_weight).error().code, ErrorCode::kInvalidInput);
  lamps::LampFrameInput bad_gamma = s.inputs[0];
  bad_gamma.photometry.gamma = 9;
  EXPECT_EQ((*shader)->setView(bad_gamma).error().code, ErrorCode::kInvalidInput);
  lamps::Material bad;
  bad.shininess = 0;
  EXPECT_EQ((*shader)->setMaterial(bad).error().code, ErrorCode::kInvalidInput);
  ASSERT_TRUE((*shader)->setView(s.inputs[0]));
  ASSERT_TRUE((*shader)->setMaterial(s.look));
  EXPECT_EQ((*shader)->shade(0, std::nullopt).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ((*shader)->shade(1, Vec3(std::nan(""), 0, 0)).error().code, ErrorCode::kInvalidInput);
  EXPECT_TRUE((*shader)->shade(s.white, std::nullopt));
}

}  // namespace
}  // namespace procam::output::gl
