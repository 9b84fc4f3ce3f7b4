// A projector's frame for shader lamps: the radiance correction of [Raskar02] eq. 5.4
// through the projector's response, the white level every projector can give, and the
// appearance (texture, virtual light, view-dependent highlight).
#include <gtest/gtest.h>

#include <cmath>

#include "lamp_rig.hpp"
#include "shader_lamps/lamp_frame.hpp"
#include "shader_lamps/lamp_gain.hpp"
#include "shader_lamps/lamp_view.hpp"

namespace procam::lamps {
namespace {

struct Lit {
  ObjectModel plate;
  geom::CameraModel p;
  LampView view;
  cv::Mat weight;
};

// A projector 2 m in front of a plate, 30 deg to its side, all its hits weighted one.
Lit lit() {
  auto plate = ObjectModel::build(test::plate(2.0, 2.0, 4));
  EXPECT_TRUE(plate);
  Lit r{std::move(*plate), test::projectorAt(Vec3(-1.1547, 0, 0), Vec3(0, 2, 0)), {}, {}};
  r.view = *castLampView(r.p, r.plate);
  r.weight = cv::Mat(r.view.size, CV_32FC1, cv::Scalar(0));
  r.weight.setTo(1.f, r.view.face >= 0);
  return r;
}

TEST(ShaderLampFrame, IntensityIsRadianceTimesDistanceSquaredOverCosine) {
  const Lit r = lit();
  LampFrameInput in{&r.view, &r.weight, {}};
  in.photometry.gamma = 2.2;
  in.photometry.gain_rgb = Vec3(2.0, 2.5, 3.0);
  Material grey;
  grey.albedo_rgb = Vec3(0.5, 0.4, 0.3);
  auto level = lampWhiteLevel(std::span<const LampFrameInput>(&in, 1));
  ASSERT_TRUE(level);
  const double white = 0.9 * *level;
  LampFrameStats stats;
  auto frame = lampFrame(in, grey, white, std::nullopt, &stats);
  ASSERT_TRUE(frame) << frame.error().message;
  ASSERT_EQ(frame->type(), CV_8UC3);
  int checked = 0;
  for (int y = 0; y < 300; y += 5) {
    for (int x = 0; x < 400; x += 5) {
      const cv::Vec3b c = frame->at<cv::Vec3b>(y, x);
      if (r.view.face.at<int>(y, x) < 0) {
        EXPECT_EQ(c, cv::Vec3b(0, 0, 0));  // off the object: no light
        continue;
      }
      const double d = r.view.distance.at<float>(y, x), cs = r.view.cosine.at<float>(y, x);
      for (int k = 0; k < 3; ++k) {
        const double want = white * grey.albedo_rgb[k] * d * d / (in.photometry.gain_rgb[k] * cs);
        // The code value that emits it, rounded (the view's floats add under 1e-4 code).
        EXPECT_NEAR(c[2 - k], 255 * std::pow(want, 1 / 2.2), 0.5 + 1e-4)
            << x << "," << y << " channel " << k;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 3000);
  EXPECT_EQ(stats.clipped_pixels, 0);
  EXPECT_GT(stats.lit_pixels, 50000);
}

TEST(ShaderLampFrame, WhiteLevelIsWhatTheDimmestPointAllows) {
  const Lit r = lit();
  LampFrameInput in{&r.view, &r.weight, {}};
  in.photometry.gain_rgb = Vec3(2.0, 2.5, 3.0);
  auto white = lampWhiteLevel(std::span<const LampFrameInput>(&in, 1));
  ASSERT_TRUE(white);
  double want = 1e300;
  for (int y = 0; y < 300; ++y)
    for (int x = 0; x < 400; ++x)
      if (r.view.face.at<int>(y, x) >= 0) {
        const double d = r.view.distance.at<float>(y, x);
        want = std::min(want, 2.0 * r.view.cosine.at<float>(y, x) / (d * d));
      }
  EXPECT_NEAR(*white, want, 1e-9 * want);
  // At that level a white object needs full light somewhere and never more.
  Material white_material;
  LampFrameStats stats;
  auto frame = lampFrame(in, white_material, *white, std::nullopt, &stats);
  ASSERT_TRUE(frame);
  double hi = 0;
  cv::minMaxLoc(frame->reshape(1), nullptr, &hi);
  EXPECT_EQ(hi, 255);
  EXPECT_EQ(stats.clipped_pixels, 0);
  // Twice as bright cannot be given everywhere: the pixels that would need it are counted.
  ASSERT_TRUE(lampFrame(in, white_material, 2 * *white, std::nullopt, &stats));
  EXPECT_GT(stats.clipped_pixels, 0);
}

TEST(ShaderLampFrame, AppearanceTexturesLightsAndHighlights) {
  Material m;
  m.texture = cv::Mat(2, 2, CV_32FC3);
  m.texture.at<cv::Vec3f>(0, 0) = {1, 0, 0};  // top left: v = 1, u = 0
  m.texture.at<cv::Vec3f>(0, 1) = {0, 1, 0};
  m.texture.at<cv::Vec3f>(1, 0) = {0, 0, 1};
  m.texture.at<cv::Vec3f>(1, 1) = {1, 1, 1};
  EXPECT_TRUE(textureAt(m.texture, Vec2(0.25, 0.75)).isApprox(Vec3(1, 0, 0)));
  EXPECT_TRUE(textureAt(m.texture, Vec2(0.75, 0.25)).isApprox(Vec3(1, 1, 1)));
  EXPECT_TRUE(textureAt(m.texture, Vec2(0.5, 0.75)).isApprox(Vec3(0.5, 0.5, 0)));
  // Past the edge, clamped to it; not a number: a corner, never NaN.
  EXPECT_TRUE(textureAt(m.texture, Vec2(1e30, -1e30)).isApprox(Vec3(1, 1, 1)));
  EXPECT_TRUE(textureAt(m.texture, Vec2(std::nan(""), 2)).allFinite());
  // A virtual light at 60 deg from the normal: ambient plus half the rest.
  Material lambert;
  lambert.light_dir = Vec3(std::sqrt(3.0), 0, 1);
  lambert.ambient = 0.2;
  const Vec3 up = Vec3::UnitZ();
  EXPECT_TRUE(desiredRadiance(lambert, Vec3::Zero(), up, Vec2::Zero(), std::nullopt)
                  .isApprox(Vec3::Constant(0.2 + 0.8 * 0.5)));
  // Blinn-Phong: the full highlight for the eye in the mirror direction, less elsewhere,
  // none without an eye.
  Material glossy;
  glossy.albedo_rgb = Vec3::Zero();
  glossy.specular_rgb = Vec3::Constant(0.5);
  glossy.light_dir = Vec3(1, 0, 1);
  const Vec3 mirror(-3, 0, 3), aside(3, 0, 3);
  EXPECT_NEAR(desiredRadiance(glossy, Vec3::Zero(), up, {}, mirror).x(), 0.5, 1e-12);
  EXPECT_LT(desiredRadiance(glossy, Vec3::Zero(), up, {}, aside).x(), 0.05);
  EXPECT_EQ(desiredRadiance(glossy, Vec3::Zero(), up, {}, std::nullopt).x(), 0.0);
}

TEST(ShaderLampFrame, BadInputIsRefused) {
  const Lit r = lit();
  LampFrameInput in{&r.view, &r.weight, {}};
  Material ok;
  EXPECT_TRUE(lampFrame(in, ok, 0.1, std::nullopt));
  EXPECT_EQ(lampFrame(in, ok, 0.0, std::nullopt).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(lampFrame(in, ok, std::nan(""), std::nullopt).error().code, ErrorCode::kInvalidInput);
  LampFrameInput bad = in;
  bad.photometry.gamma = 0.5;
  EXPECT_EQ(lampFrame(bad, ok, 0.1, std::nullopt).error().code, ErrorCode::kInvalidInput);
  bad = in;
  bad.photometry.gain_rgb = Vec3(1, 0, 1);
  EXPECT_EQ(lampFrame(bad, ok, 0.1, std::nullopt).error().code, ErrorCode::kInvalidInput);
  const cv::Mat small(10, 10, CV_32FC1, cv::Scalar(1));
  bad = in;
  bad.weight = &small;
  EXPECT_EQ(lampFrame(bad, ok, 0.1, std::nullopt).error().code, ErrorCode::kInvalidInput);
  Material m;
  m.shininess = 0;
  EXPECT_EQ(lampFrame(in, m, 0.1, std::nullopt).error().code, ErrorCode::kInvalidInput);
  m = {};
  m.texture = cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(0));
  EXPECT_EQ(lampFrame(in, m, 0.1, std::nullopt).error().code, ErrorCode::kInvalidInput);
  m = {};
  m.light_dir = Vec3::Zero();
  EXPECT_EQ(lampFrame(in, m, 0.1, std::nullopt).error().code, ErrorCode::kInvalidInput);
  const LampFrameInput none{};
  EXPECT_EQ(lampFrame(none, ok, 0.1, std::nullopt).error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::lamps

namespace procam::lamps {
namespace {

// k·B from a camera's white and black captures of the plate: the camera's codes are
// black + k·B cos θ / d² wherever the projector lights the plate.
TEST(ShaderLampGain, WhiteMinusBlackTimesDistanceSquaredOverCosine) {
  auto plate = ObjectModel::build(test::plate(2.0, 2.0, 4));
  ASSERT_TRUE(plate);
  const geom::CameraModel projector = test::projectorAt(Vec3(-0.5, 0, 0.1), Vec3(0, 2, 0));
  const geom::CameraModel camera = test::projectorAt(Vec3(0.4, 0.2, -0.1), Vec3(0, 2, 0));
  auto view = castLampView(projector, *plate);
  ASSERT_TRUE(view);
  const Lamp lamps[] = {{&projector, &*view, true}};
  auto weights = lampWeights(lamps);
  ASSERT_TRUE(weights);
  const Vec3 gain(9000, 11000, 13000);  // R, G, B
  cv::Mat white(camera.height, camera.width, CV_16UC3, cv::Scalar::all(100));
  const cv::Mat black = white.clone();
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const auto ray = camera.backproject(Vec2(x, y));
      const auto s = plate->intersect(*ray);
      if (!s) continue;
      const auto q = projector.project(s->point);
      if (!q || !projector.inImage(*q)) continue;
      const Vec3 to = projector.pose.center() - s->point;
      const Vec3 v = gain * s->normal.dot(to.normalized()) / to.squaredNorm();
      white.at<cv::Vec3w>(y, x) += cv::Vec3w(static_cast<std::uint16_t>(std::lround(v.z())),
                                             static_cast<std::uint16_t>(std::lround(v.y())),
                                             static_cast<std::uint16_t>(std::lround(v.x())));
    }
  }
  const GainCapture capture{&camera, white, black, 65535, 2};
  auto m = measureLampGain(lamps, *weights, 0, *plate, capture);
  ASSERT_TRUE(m) << m.error().message;
  EXPECT_GT(m->samples, 5000);
  // Codes rounded to one in about 2500: the median is within a few in 10^4.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(m->gain_rgb[c], gain[c], 1e-3 * gain[c]);
  EXPECT_LT(m->spread, 1e-3);
  // No light: nothing to measure. Wrong images or index: refused.
  EXPECT_EQ(
      measureLampGain(lamps, *weights, 0, *plate, {&camera, black, black, 65535, 2}).error().code,
      ErrorCode::kTooFewPoints);
  EXPECT_EQ(measureLampGain(lamps, *weights, 1, *plate, capture).error().code,
            ErrorCode::kInvalidInput);
  const cv::Mat small(10, 10, CV_16UC3, cv::Scalar::all(0));
  EXPECT_EQ(
      measureLampGain(lamps, *weights, 0, *plate, {&camera, small, small, 65535, 2}).error().code,
      ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::lamps

namespace procam::lamps {
namespace {

// k·B from a brightness map: brightness = k·B cos θ / d² wherever the projector lights
// the plate gives k·B back, grey.
TEST(ShaderLampGain, FromABrightnessMap) {
  const Lit r = lit();
  const Lamp lamps[] = {{&r.p, &r.view, true}};
  auto weights = lampWeights(lamps);
  ASSERT_TRUE(weights);
  const auto brightness = [&](const Vec2& px) {
    const int x = static_cast<int>(px.x()), y = static_cast<int>(px.y());
    const double d = r.view.distance.at<float>(y, x);
    return 250.0 * r.view.cosine.at<float>(y, x) / (d * d);
  };
  auto gain = gainFromBrightness(r.view, weights->reach[0], brightness);
  ASSERT_TRUE(gain) << gain.error().message;
  EXPECT_NEAR(gain->gain_rgb.x(), 250, 1e-6 * 250);
  EXPECT_EQ(gain->gain_rgb.x(), gain->gain_rgb.z());
  const auto none = [](const Vec2&) { return 0.0; };
  EXPECT_EQ(gainFromBrightness(r.view, weights->reach[0], none).error().code,
            ErrorCode::kTooFewPoints);
}

TEST(ShaderLampFrame, SixteenBitFramesKeepTheFinerCodes) {
  const Lit r = lit();
  LampFrameInput in{&r.view, &r.weight, {}};
  auto level = lampWhiteLevel(std::span<const LampFrameInput>(&in, 1));
  ASSERT_TRUE(level);
  Material grey;
  grey.albedo_rgb = Vec3::Constant(0.3);
  auto frame = lampFrame(in, grey, *level, std::nullopt, nullptr, 16);
  ASSERT_TRUE(frame);
  ASSERT_EQ(frame->type(), CV_16UC3);
  for (int y = 0; y < 300; y += 11) {
    for (int x = 0; x < 400; x += 11) {
      if (r.view.face.at<int>(y, x) < 0) continue;
      const double d = r.view.distance.at<float>(y, x), c = r.view.cosine.at<float>(y, x);
      const double want = *level * 0.3 * d * d / c;
      EXPECT_NEAR(frame->at<cv::Vec3w>(y, x)[1], 65535 * std::pow(want, 1 / 2.2), 0.5 + 0.05);
    }
  }
  EXPECT_EQ(lampFrame(in, grey, *level, std::nullopt, nullptr, 12).error().code,
            ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::lamps
