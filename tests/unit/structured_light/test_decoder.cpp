#include <gtest/gtest.h>

#include "structured_light/decoder.hpp"
#include "structured_light/pattern_set.hpp"
#include "synthetic_view.hpp"

using namespace procam;
using namespace procam::sl;
using procam::testing::kCamera;
using procam::testing::kProjH;
using procam::testing::kProjW;
using procam::testing::ViewModel;

namespace {

ViewModel obliqueView() {
  ViewModel m;
  const cv::Matx33d H(1.15, 0.08, 12, -0.05, 1.1, 15, 2e-4, 1e-4, 1);
  procam::testing::homographyMaps(H, kCamera, m.map_x, m.map_y);
  return m;
}

std::vector<cv::Mat> capture(const PatternSet& set, const ViewModel& m) {
  std::vector<cv::Mat> out;
  for (std::size_t i = 0; i < set.frames.size(); ++i)
    out.push_back(
        procam::testing::viewFrame(renderFrame(set, i), m, static_cast<std::uint32_t>(i)));
  return out;
}

struct ErrorStats {
  double rms = 0, max = 0;
  double decoded_fraction = 0;
};

ErrorStats compare(const Decoded& d, const ViewModel& m) {
  ErrorStats s;
  double sum = 0;
  int n = 0;
  for (int y = 0; y < d.u.rows; ++y)
    for (int x = 0; x < d.u.cols; ++x) {
      if (d.flags.at<std::uint8_t>(y, x) != 0) continue;
      const double eu = d.u.at<float>(y, x) - m.map_x.at<float>(y, x);
      const double ev = d.v.at<float>(y, x) - m.map_y.at<float>(y, x);
      sum += eu * eu + ev * ev;
      s.max = std::max({s.max, std::abs(eu), std::abs(ev)});
      ++n;
    }
  // Per-axis RMS (the "projector px RMS" of the decoding bounds, one coordinate).
  s.rms = n ? std::sqrt(sum / (2.0 * n)) : 1e9;
  s.decoded_fraction = static_cast<double>(n) / d.u.total();
  EXPECT_EQ(n, d.decoded);
  return s;
}

// Every camera pixel that sees the projector's image at least one projector pixel
// inside its edge is decoded (the view's top-right corner maps just above the
// projector: those pixels are only partly lit, and the decoder drops them).
void expectInteriorDecoded(const Decoded& d, const ViewModel& m) {
  int interior = 0, missed = 0;
  for (int y = 0; y < d.u.rows; ++y)
    for (int x = 0; x < d.u.cols; ++x) {
      const float px = m.map_x.at<float>(y, x), py = m.map_y.at<float>(y, x);
      if (px < 0.5f || py < 0.5f || px > kProjW - 1.5f || py > kProjH - 1.5f) continue;
      ++interior;
      missed += d.flags.at<std::uint8_t>(y, x) != 0;
    }
  EXPECT_GT(interior, 0.99 * d.u.total());
  EXPECT_EQ(missed, 0);
}

}  // namespace

TEST(Decoder, GrayNoiselessDecodesEveryPixelWithinOneCell) {
  ViewModel m = obliqueView();
  m.noise_dn = 0;
  m.projector_gamma = 1;
  m.ambient = 0;
  auto set = makePatternSet({.width = kProjW, .height = kProjH});
  ASSERT_TRUE(set);
  auto d = decode(*set, capture(*set, m));
  ASSERT_TRUE(d);
  const ErrorStats s = compare(*d, m);
  expectInteriorDecoded(*d, m);
  // Cell centre against a continuous position: |error| <= 0.5 inside a cell, one
  // cell more at an edge where the flipping bit is ambiguous.
  EXPECT_LE(s.max, 1.5);
  EXPECT_LE(s.rms, 0.5);
}

// The reference capture conditions: read noise 1 DN on 8 bits, gamma 2.2, ambient 10%, plus a
// mild defocus. Gray alone: <= 0.5 px RMS.
TEST(Decoder, GrayMeetsHalfPixelUnderGammaAmbientNoiseDefocus) {
  for (double camera_gamma : {1.0, 2.2}) {
    ViewModel m = obliqueView();
    m.defocus_sigma = 0.7;
    m.camera_gamma = camera_gamma;
    auto set = makePatternSet({.width = kProjW, .height = kProjH});
    ASSERT_TRUE(set);
    auto d = decode(*set, capture(*set, m));
    ASSERT_TRUE(d);
    const ErrorStats s = compare(*d, m);
    EXPECT_GE(s.decoded_fraction, 0.9) << "camera gamma " << camera_gamma;
    EXPECT_LE(s.rms, 0.5) << "camera gamma " << camera_gamma;
    EXPECT_LE(s.max, 1.5) << "camera gamma " << camera_gamma;
  }
}

// Gray + phase: <= 0.1 projector px RMS, for 3 and 8 steps.
TEST(Decoder, GrayPhaseMeetsTenthPixel) {
  for (int steps : {3, 8}) {
    ViewModel m = obliqueView();
    m.defocus_sigma = 0.7;
    auto set = makePatternSet(
        {.width = kProjW, .height = kProjH, .mode = Mode::kGrayPhase, .phase_steps = steps});
    ASSERT_TRUE(set);
    auto d = decode(*set, capture(*set, m));
    ASSERT_TRUE(d);
    const ErrorStats s = compare(*d, m);
    EXPECT_GE(s.decoded_fraction, 0.95) << steps << " steps";
    EXPECT_LE(s.rms, 0.1) << steps << " steps";
  }
}

// A camera with a non-linear response (code = signal^(1/2.2)): the decoder estimates
// the exponent from the captures and linearises the phase frames, so 3-step phase
// still meets 0.1 px; taken as linear, the response's harmonics alias onto the
// 3-step phase and the error is several times larger.
TEST(Decoder, GrayPhaseLinearisesTheCameraResponse) {
  for (int steps : {3, 8}) {
    ViewModel m = obliqueView();
    m.defocus_sigma = 0.7;
    m.camera_gamma = 2.2;
    auto set = makePatternSet(
        {.width = kProjW, .height = kProjH, .mode = Mode::kGrayPhase, .phase_steps = steps});
    ASSERT_TRUE(set);
    const auto captures = capture(*set, m);
    auto d = decode(*set, captures);
    ASSERT_TRUE(d);
    EXPECT_NEAR(d->response_gamma, 2.2, 0.1) << steps << " steps";
    const ErrorStats s = compare(*d, m);
    EXPECT_GE(s.decoded_fraction, 0.95) << steps << " steps";
    EXPECT_LE(s.rms, 0.1) << steps << " steps";
    if (steps == 3) {
      auto linear = decode(*set, captures, {.response_gamma = 1});
      ASSERT_TRUE(linear);
      EXPECT_EQ(linear->response_gamma, 1.0);
      EXPECT_GT(compare(*linear, m).rms, 2 * s.rms);
    }
  }
  // A linear camera is found linear (no table, the phase frames used as captured).
  ViewModel m = obliqueView();
  auto set = makePatternSet(
      {.width = kProjW, .height = kProjH, .mode = Mode::kGrayPhase, .phase_steps = 4});
  auto d = decode(*set, capture(*set, m));
  ASSERT_TRUE(d);
  EXPECT_EQ(d->response_gamma, 1.0);
}

TEST(Decoder, SixteenBitCapturesDecodeLikeEightBit) {
  ViewModel m = obliqueView();
  m.sixteen_bit = true;
  m.noise_dn = 257;  // 1 DN of 8 bits
  auto set = makePatternSet(
      {.width = kProjW, .height = kProjH, .mode = Mode::kGrayPhase, .phase_steps = 4});
  ASSERT_TRUE(set);
  const auto captures = capture(*set, m);
  ASSERT_EQ(captures[0].depth(), CV_16U);
  auto d = decode(*set, captures);
  ASSERT_TRUE(d);
  const ErrorStats s = compare(*d, m);
  EXPECT_GE(s.decoded_fraction, 0.95);
  EXPECT_LE(s.rms, 0.1);
}

// A 10-bit sensor's codes in 16-bit images: the full scale follows the white frame.
TEST(Decoder, TenBitCodesInSixteenBitImages) {
  ViewModel m = obliqueView();
  m.sixteen_bit = true;
  m.noise_dn = 257;
  auto set = makePatternSet({.width = kProjW, .height = kProjH});
  ASSERT_TRUE(set);
  auto captures = capture(*set, m);
  for (auto& c : captures) c.convertTo(c, CV_16U, 1023.0 / 65535.0);
  auto d = decode(*set, captures);
  ASSERT_TRUE(d);
  const ErrorStats s = compare(*d, m);
  EXPECT_GE(s.decoded_fraction, 0.9);
  EXPECT_LE(s.rms, 0.5);
}

TEST(Decoder, StepDecodesCellCentres) {
  ViewModel m = obliqueView();
  m.noise_dn = 0;
  auto set = makePatternSet({.width = kProjW, .height = kProjH, .step = 8});
  ASSERT_TRUE(set);
  EXPECT_EQ(set->frames.size(), 2u + 2 * 6 + 2 * 6);  // 50 and 38 cells: 6 bits each
  auto d = decode(*set, capture(*set, m));
  ASSERT_TRUE(d);
  const ErrorStats s = compare(*d, m);
  expectInteriorDecoded(*d, m);
  // Uniform error over a cell of 8: RMS 8/sqrt(12) = 2.31, max 4 (+ one cell at edges).
  EXPECT_LE(s.max, 12.0);
  EXPECT_NEAR(s.rms, 8 / std::sqrt(12.0), 0.4);
}

TEST(Decoder, MasksShadowSaturationLowContrastAndInconsistentBits) {
  ViewModel m = obliqueView();
  m.gain = 0.5;
  // Camera columns 0..19 see nothing of the projector (outside its image).
  m.map_x.colRange(0, 20).setTo(-1000);
  auto set = makePatternSet({.width = kProjW, .height = kProjH});
  ASSERT_TRUE(set);
  auto captures = capture(*set, m);
  const cv::Rect saturated(100, 10, 10, 10), flat(150, 10, 10, 10), corrupt(200, 10, 10, 10);
  for (auto& c : captures) c(saturated).setTo(255);
  // Pattern and inverse equal (no stripe contrast) while white/black stay apart.
  for (std::size_t i = 2; i < captures.size(); ++i) captures[i](flat).setTo(90);
  // One pattern frame brighter than the all-white frame.
  captures[4](corrupt).setTo(250);
  auto d = decode(*set, captures);
  ASSERT_TRUE(d);
  auto flagsIn = [&](const cv::Rect& r) {
    int all = 0xff;
    for (int y = r.y; y < r.y + r.height; ++y)
      for (int x = r.x; x < r.x + r.width; ++x) all &= d->flags.at<std::uint8_t>(y, x);
    return all;
  };
  EXPECT_TRUE(flagsIn(cv::Rect(0, 0, 20, 240)) & kShadow);
  EXPECT_TRUE(flagsIn(saturated) & kSaturated);
  EXPECT_TRUE(flagsIn(flat) & kLowContrast);
  EXPECT_TRUE(flagsIn(corrupt) & kInconsistent);
  for (const cv::Rect& r : {saturated, flat, corrupt}) {
    EXPECT_EQ(cv::countNonZero(d->u(r) != -1.0f), 0);
    EXPECT_EQ(cv::countNonZero(d->confidence(r)), 0);
  }
  // Elsewhere decoded, with a confidence well above zero.
  EXPECT_EQ(d->flags.at<std::uint8_t>(200, 300), 0);
  EXPECT_GT(d->confidence.at<float>(200, 300), 0.3f);
}

TEST(Decoder, RejectsWrongInput) {
  auto set = makePatternSet({.width = 64, .height = 48});
  ASSERT_TRUE(set);
  std::vector<cv::Mat> frames(set->frames.size(), cv::Mat(48, 64, CV_8UC1, cv::Scalar(0)));
  EXPECT_EQ(decode(*set, std::span(frames).first(3)).error().code, ErrorCode::kInvalidInput);
  frames[5] = cv::Mat(40, 64, CV_8UC1, cv::Scalar(0));
  EXPECT_EQ(decode(*set, frames).error().code, ErrorCode::kInvalidInput);
  frames[5] = cv::Mat(48, 64, CV_32FC1, cv::Scalar(0));
  EXPECT_EQ(decode(*set, frames).error().code, ErrorCode::kInvalidInput);
  frames[5] = cv::Mat(48, 64, CV_16UC1, cv::Scalar(0));
  EXPECT_EQ(decode(*set, frames).error().code, ErrorCode::kInvalidInput);
}
