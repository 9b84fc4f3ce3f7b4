// Alpha mask with the weight LUT ([Raskar02] §4.1.2) and the output LUT.
#include <gtest/gtest.h>

#include <cmath>

#include "render/final_stage.hpp"
#include "render_test_images.hpp"

namespace procam::render {
namespace {

double light(int code, double gamma) {
  return std::pow(code / 255.0, gamma);
}

int blended(int c, int alpha, const Lut& lut) {
  return (c * lut[alpha] + 127) / 255;
}

TEST(FinalStage, ComplementaryMasksSumToTheContentLightThroughTheWeightLut) {
  // Two projectors with code^gamma response and masks a, 255 - a: with the weight LUT
  // the emitted light sums to the content's. Each code is rounded twice (LUT, product),
  // <= 1 code value; light changes by <= gamma/255 per code value, so the sum is within
  // 2 gamma / 255 of the content light.
  const double gamma = 2.2;
  auto lut = weightLutForGamma(gamma);
  ASSERT_TRUE(lut);
  for (int c : {64, 128, 200, 255}) {
    for (int a = 0; a <= 255; ++a) {
      const double sum =
          light(blended(c, a, *lut), gamma) + light(blended(c, 255 - a, *lut), gamma);
      EXPECT_NEAR(sum, light(c, gamma), 2 * gamma / 255) << "c=" << c << " a=" << a;
    }
  }
  // Without the LUT the half-way point loses more than half the light: the LUT matters.
  const Lut id = FinalStage::identityLut();
  const double flat = 2 * light(blended(200, 128, id), gamma);
  EXPECT_LT(flat, 0.5 * light(200, gamma));
}

TEST(FinalStage, AppliesMaskToColourOnlyThenOutputLut) {
  cv::Mat img(2, 2, CV_8UC4, cv::Scalar(200, 100, 50, 77));
  FinalStage s;
  s.alpha = (cv::Mat_<uint8_t>(2, 2) << 255, 0, 128, 64);
  for (int i = 0; i < 256; ++i) s.output_lut[1][i] = static_cast<uint8_t>(255 - i);
  ASSERT_TRUE(applyFinalStage(s, img));
  EXPECT_EQ(img.at<cv::Vec4b>(0, 0), cv::Vec4b(200, 155, 50, 77));
  EXPECT_EQ(img.at<cv::Vec4b>(0, 1), cv::Vec4b(0, 255, 0, 77));
  EXPECT_EQ(img.at<cv::Vec4b>(1, 0),
            cv::Vec4b((200 * 128 + 127) / 255, 255 - (100 * 128 + 127) / 255,
                      (50 * 128 + 127) / 255, 77));
  cv::Mat wrong(3, 3, CV_8UC4);
  EXPECT_EQ(applyFinalStage(s, wrong).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(weightLutForGamma(0).error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::render
