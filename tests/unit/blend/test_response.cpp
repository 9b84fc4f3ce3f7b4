// A projector's response from a grey ramp, brightness matching and the weight table.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "blend/response.hpp"

namespace procam::blend {
namespace {

// The ramp procamd shows (levels 0, 32, ..., 224, 255) seen by a linear camera:
// black + (white - black) (g/255)^gamma, each mean with `noise` camera units of error.
std::vector<RampSample> ramp(double gamma, double black, double white, double noise) {
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0, noise);
  std::vector<RampSample> out;
  for (int g : {0, 32, 64, 96, 128, 160, 192, 224, 255})
    out.push_back({g, black + (white - black) * std::pow(g / 255.0, gamma) + n(rng)});
  return out;
}

// Means over thousands of camera pixels carry about 0.05 units of error; the fit
// then holds gamma to 0.01 (d gamma = d m / (m ln(g/255)), at g = 96 with m ~ 20).
TEST(Response, GammaAndLevelsFromARamp) {
  for (double gamma : {2.0, 2.2, 2.6}) {
    const auto r = fitResponse(ramp(gamma, 3.0, 180.0, 0.05));
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_NEAR(r->gamma, gamma, 0.01);
    EXPECT_NEAR(r->black, 3.0, 0.2);
    EXPECT_NEAR(r->white, 180.0, 0.2);
    EXPECT_LT(r->rms, 0.01);
    EXPECT_GE(r->levels, 5);
  }
}

TEST(Response, BadRampsAreRefused) {
  EXPECT_EQ(fitResponse(std::vector<RampSample>{}).error().code, ErrorCode::kTooFewPoints);
  auto flat = ramp(2.2, 10, 12, 0);
  EXPECT_EQ(fitResponse(flat).error().code, ErrorCode::kDegenerate);
  auto nan = ramp(2.2, 3, 180, 0);
  nan[3].mean = std::nan("");
  EXPECT_EQ(fitResponse(nan).error().code, ErrorCode::kInvalidInput);
  const std::vector<RampSample> ends{{0, 3}, {255, 180}};
  EXPECT_EQ(fitResponse(ends).error().code, ErrorCode::kTooFewPoints);
  auto linear = ramp(0.5, 3, 180, 0);  // brighter than linear: no projector
  EXPECT_EQ(fitResponse(linear).error().code, ErrorCode::kDegenerate);
}

TEST(Response, GainsBringEveryWhiteToTheDimmest) {
  std::vector<ProjectorResponse> rs(3);
  rs[0].white = 110;
  rs[1].white = 90;
  rs[2].white = 130;
  for (auto& r : rs) r.black = 10;
  const auto g = matchedGains(rs);
  ASSERT_EQ(g.size(), 3u);
  EXPECT_NEAR(g[0], 0.8, 1e-12);
  EXPECT_NEAR(g[1], 1.0, 1e-12);
  EXPECT_NEAR(g[2], 80.0 / 120, 1e-12);
}

// The table gives code c with (c/255)^gamma = gain * a/255: light proportional to the
// weight, to within one code's rounding.
TEST(Response, WeightTableEmitsLightInProportionToTheWeight) {
  const auto lut = weightLut(2.6, 0.8);
  ASSERT_TRUE(lut);
  for (int a : {0, 64, 128, 255}) {
    const double light = std::pow((*lut)[a] / 255.0, 2.6);
    const double step = 2.6 * std::pow(std::max(1, int((*lut)[a])) / 255.0, 1.6) / 255;
    EXPECT_NEAR(light, 0.8 * a / 255.0, step) << a;
  }
  EXPECT_FALSE(weightLut(2.2, 0.0));
  EXPECT_FALSE(weightLut(2.2, 1.5));
  EXPECT_FALSE(weightLut(-1, 0.5));
}

}  // namespace
}  // namespace procam::blend
