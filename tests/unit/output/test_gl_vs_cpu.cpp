// The GLES 3 back-end on Mesa's surfaceless EGL against the CPU reference on the same
// inputs (bound: mean abs difference <= 1/255 and PSNR >= 45 dB away from borders).
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "headless/headless_output.hpp"
#include "render/bilinear.hpp"
#include "render/cpu_renderer.hpp"
#include "render_test_images.hpp"
#include "render_test_rig.hpp"

namespace procam::output {
namespace {

using render::RenderPath;
using render::RenderSetup;

// Pixels at least `margin` px inside both the output frame and the region the CPU
// map's source footprint covers (content edges and mesh silhouettes excluded).
cv::Mat interior(const RenderSetup& s, const render::WarpMap& map, int margin) {
  cv::Mat valid(map.xy.size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < valid.rows; ++y) {
    for (int x = 0; x < valid.cols; ++x) {
      const cv::Vec2f p = map.xy.at<cv::Vec2f>(y, x);
      valid.at<uint8_t>(y, x) =
          render::insideFootprint(p[0], p[1], s.content_size.width, s.content_size.height) ? 255
                                                                                           : 0;
    }
  }
  cv::Mat framed(valid.size(), CV_8UC1, cv::Scalar(0));
  valid(cv::Rect(1, 1, valid.cols - 2, valid.rows - 2))
      .copyTo(framed(cv::Rect(1, 1, valid.cols - 2, valid.rows - 2)));
  cv::Mat out;
  cv::erode(framed, out, cv::Mat::ones(2 * margin + 1, 2 * margin + 1, CV_8UC1));
  return out;
}

struct Frames {
  cv::Mat gl, cpu, mask;
};

Frames renderBoth(HeadlessOutput& out, const RenderSetup& setup, const cv::Mat& content) {
  Frames f;
  render::CpuRenderer cpu;
  EXPECT_TRUE(cpu.configure(setup));
  EXPECT_TRUE(cpu.render({&content, nullptr, 1}));
  EXPECT_TRUE(cpu.readFrame(f.cpu));
  auto ok = out.configure(setup);
  EXPECT_TRUE(ok) << (ok ? "" : ok.error().message);
  auto shown = out.show({&content, nullptr, 1});
  EXPECT_TRUE(shown && *shown) << (shown ? "" : shown.error().message);
  f.gl = out.lastFrame().clone();
  if (std::getenv("PROCAM_DUMP")) {
    cv::imwrite("/tmp/gl.png", f.gl);
    cv::imwrite("/tmp/cpu.png", f.cpu);
  }
  f.mask = interior(setup, cpu.map(), 3);
  return f;
}

void expectClose(const Frames& f, const char* what) {
  const test::Difference d = test::compare(f.gl, f.cpu, f.mask);
  ::testing::Test::RecordProperty(std::string(what) + "_mean_abs", std::to_string(d.mean_abs));
  ::testing::Test::RecordProperty(std::string(what) + "_psnr", std::to_string(d.psnr));
  EXPECT_GT(d.pixels, f.gl.total() / 4) << what << ": too few interior pixels compared";
  EXPECT_LE(d.mean_abs, 1.0) << what;  // 1/255 of full scale
  EXPECT_GE(d.psnr, 45.0) << what;
  std::printf("%s: mean abs %.4f, max %.0f, PSNR %.2f dB over %ld px\n", what, d.mean_abs,
              d.max_abs, d.psnr, d.pixels);
}

class GlVsCpu : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto o = HeadlessOutput::create({640, 480});
    ASSERT_TRUE(o) << o.error().message;
    out_ = std::move(*o);
    std::printf("GL renderer: %s\n", out_->glRenderer().c_str());
  }
  static void TearDownTestSuite() { out_.reset(); }
  static std::unique_ptr<HeadlessOutput> out_;
};
std::unique_ptr<HeadlessOutput> GlVsCpu::out_;

RenderSetup homographySetup() {
  RenderSetup s;
  s.output_size = {640, 480};
  s.content_size = {512, 384};
  s.path = RenderPath::kHomography;
  s.homography << 1.05, 0.12, 40, -0.08, 0.98, 45, 2.5e-4, -1.5e-4, 1;
  return s;
}

TEST_F(GlVsCpu, HomographyWarp) {
  const RenderSetup s = homographySetup();
  expectClose(renderBoth(*out_, s, test::detailedImage(s.content_size, 1)), "homography");
}

TEST_F(GlVsCpu, MeshWarpTwoPassProjectiveTexture) {
  RenderSetup s;
  s.output_size = {640, 480};
  s.content_size = {512, 512};
  s.path = RenderPath::kTwoPassMesh;
  s.surface = test::domeMesh(Vec3(0, 0, 0), 2.0, 16, 48);
  s.projector = test::lookAtProjection(520, 319.5, 239.5, Vec3(0.3, 0.2, 0.1), Vec3(0.3, 2, 0.5),
                                       Vec3::UnitZ());
  s.viewer = test::lookAtProjection(300, 255.5, 255.5, Vec3(-0.2, 0.1, -0.3), Vec3(0, 2, 0.2),
                                    Vec3::UnitZ());
  expectClose(renderBoth(*out_, s, test::detailedImage(s.content_size, 2)), "mesh");
}

TEST_F(GlVsCpu, PostRenderWarpGrid) {
  RenderSetup s = homographySetup();
  render::WarpGrid g;
  g.step = Vec2(8, 8);
  g.cols = 640 / 8 + 1;
  g.rows = 480 / 8 + 1;
  for (int j = 0; j < g.rows; ++j) {
    for (int i = 0; i < g.cols; ++i) {
      const Vec2 n = g.node(i, j);
      // Smooth residual of a few pixels, as left by an imperfect projection matrix.
      g.source.push_back(n + Vec2(2.5 * std::sin(n.y() / 70.0), 1.8 * std::cos(n.x() / 90.0)));
    }
  }
  s.post_warp = g;
  expectClose(renderBoth(*out_, s, test::detailedImage(s.content_size, 3)), "post-warp");
}

TEST_F(GlVsCpu, BlendedOverlapOfTwoProjectors) {
  // Two projectors tile one plane side by side; each has a feathered alpha mask across the
  // overlap, the gamma weight LUT and an output LUT.
  const cv::Size out(640, 480), content(900, 400);
  auto weight = render::weightLutForGamma(2.2);
  ASSERT_TRUE(weight);
  for (int k = 0; k < 2; ++k) {
    RenderSetup s;
    s.output_size = out;
    s.content_size = content;
    // Content x in [0, 900): projector 0 shows [0, 520), projector 1 [380, 900).
    const double x0 = k == 0 ? 0 : 380;
    s.homography << 640.0 / 520, 0.03, -x0 * 640.0 / 520 + 5, 0.02, 1.15, 10, 1e-4 * (k ? -1 : 1),
        0, 1;
    s.final_stage.alpha = cv::Mat(out, CV_8UC1);
    for (int y = 0; y < out.height; ++y) {
      for (int x = 0; x < out.width; ++x) {
        const double cx = x0 + x * 520.0 / 640;  // approximate content column
        const double t = std::clamp((cx - 380) / 140.0, 0.0, 1.0);
        s.final_stage.alpha.at<uint8_t>(y, x) =
            static_cast<uint8_t>(std::lround(255 * (k ? t : 1 - t)));
      }
    }
    s.final_stage.weight_lut = *weight;
    for (int i = 0; i < 256; ++i) {
      s.final_stage.output_lut[0][i] =
          static_cast<uint8_t>(std::lround(255 * std::pow(i / 255.0, 0.9)));
      s.final_stage.output_lut[2][i] = static_cast<uint8_t>(std::min(255, i + 3));
    }
    auto o = HeadlessOutput::create(out);
    ASSERT_TRUE(o);
    expectClose(renderBoth(**o, s, test::detailedImage(content, 4)), k ? "blend-1" : "blend-0");
  }
}

TEST_F(GlVsCpu, UnchangedFrameIsNotRenderedAndPngIsWritten) {
  const RenderSetup s = homographySetup();
  auto configured = out_->configure(s);
  ASSERT_TRUE(configured) << configured.error().message;
  const cv::Mat content = test::detailedImage(s.content_size, 5);
  uint64_t sunk = 0;
  out_->setSink([&](const cv::Mat& f, uint64_t) { sunk += f.total() > 0; });
  EXPECT_TRUE(*out_->show({&content, nullptr, 7}));
  EXPECT_FALSE(*out_->show({&content, nullptr, 7}));
  EXPECT_TRUE(*out_->show({&content, nullptr, 8}));
  EXPECT_EQ(sunk, 2u);
  out_->setSink(nullptr);
  const std::string path = ::testing::TempDir() + "procam_headless_frame.png";
  ASSERT_TRUE(out_->writePng(path));
  cv::Mat back = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(back.type(), CV_8UC4);
  cv::cvtColor(back, back, cv::COLOR_BGRA2RGBA);
  EXPECT_EQ(cv::norm(back, out_->lastFrame(), cv::NORM_INF), 0.0);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace procam::output
