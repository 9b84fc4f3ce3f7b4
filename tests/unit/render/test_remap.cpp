// The per-frame remap against the double-precision bilinear specification.
#include <gtest/gtest.h>

#include <random>

#include "render/bilinear.hpp"
#include "render/packed_map.hpp"
#include "render/remap_rgba.hpp"
#include "render_test_images.hpp"

namespace procam::render {
namespace {

// Random sub-pixel map covering the source footprint and beyond it.
WarpMap randomMap(cv::Size out, cv::Size src, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> ux(-2.0f, src.width + 1.0f), uy(-2.0f, src.height + 1.0f);
  WarpMap m{cv::Mat(out, CV_32FC2)};
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) m.xy.at<cv::Vec2f>(y, x) = cv::Vec2f(ux(rng), uy(rng));
  return m;
}

TEST(Remap, WithinTheQuantisationBoundOfTheDoubleSpecification) {
  // Positions are quantised to 1/128 px (error <= 1/256 per axis) and the result rounded
  // once: |out - exact| <= (Gx + Gy) / 256 + 1/2, Gx/Gy the largest neighbour differences
  // (255 for random content), so <= 2.5 code values.
  const cv::Size src(97, 61), out(120, 80);
  const cv::Mat img = test::randomImage(src, 3);
  const WarpMap map = randomMap(out, src, 4);
  auto packed = packMap(map, src, static_cast<int>(img.step));
  ASSERT_TRUE(packed);
  cv::Mat dst;
  ASSERT_TRUE(remapRgba(img, *packed, dst));
  double worst = 0;
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      const cv::Vec2f s = map.xy.at<cv::Vec2f>(y, x);
      const cv::Vec4d e = sampleBilinear(img, s[0], s[1]);
      for (int c = 0; c < 4; ++c)
        worst = std::max(worst, std::abs(dst.at<cv::Vec4b>(y, x)[c] - e[c]));
    }
  }
  EXPECT_LE(worst, 2.0 * 255.0 / 256.0 + 0.5);
}

TEST(Remap, SmoothContentStaysWithinOneCodeValue) {
  // Smooth content: G = 127.5 * 0.05 per axis -> bound 2 * 6.4 / 256 + 0.5 < 1.
  const cv::Size src(200, 150);
  const cv::Mat img = test::smoothImage(src, 0.05, 0.05);
  const WarpMap map = randomMap({150, 100}, src, 5);
  auto packed = packMap(map, src);
  ASSERT_TRUE(packed);
  cv::Mat dst;
  ASSERT_TRUE(remapRgba(img, *packed, dst));
  for (int y = 0; y < dst.rows; ++y) {
    for (int x = 0; x < dst.cols; ++x) {
      const cv::Vec2f s = map.xy.at<cv::Vec2f>(y, x);
      const cv::Vec4d e = sampleBilinear(img, s[0], s[1]);
      for (int c = 0; c < 4; ++c) {
        ASSERT_LE(std::abs(dst.at<cv::Vec4b>(y, x)[c] - e[c]), 0.5 + 2 * 6.375 / 256 + 1e-9)
            << x << "," << y;
      }
    }
  }
}

TEST(Remap, SimdAndScalarKernelsAgreeBitForBit) {
  const cv::Size src(333, 211);
  const cv::Mat img = test::randomImage(src, 8);
  WarpMap map = randomMap({301, 199}, src, 9);
  // A band no source pixel reaches, as around a keystoned image: whole SIMD steps outside.
  map.xy(cv::Rect(16, 40, 64, 30)).setTo(cv::Scalar::all(kOutside));
  auto packed = packMap(map, src);
  ASSERT_TRUE(packed);
  // Width 301: every SIMD kernel also runs its scalar tail.
  cv::Mat best, sse2, scalar;
  ASSERT_TRUE(remapRgba(img, *packed, best, RemapKernel::kBest));
  ASSERT_TRUE(remapRgba(img, *packed, sse2, RemapKernel::kSse2));
  ASSERT_TRUE(remapRgba(img, *packed, scalar, RemapKernel::kScalar));
  EXPECT_EQ(cv::norm(best, scalar, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(sse2, scalar, cv::NORM_INF), 0.0);
}

TEST(Remap, HonoursRowStepOfSubImagesAndRejectsMismatches) {
  const cv::Mat big = test::randomImage({64, 48}, 10);
  const cv::Mat roi = big(cv::Rect(5, 3, 40, 30));
  const WarpMap id = identityMap({40, 30});
  auto packed = packMap(id, roi.size(), static_cast<int>(roi.step));
  ASSERT_TRUE(packed);
  cv::Mat dst;
  ASSERT_TRUE(remapRgba(roi, *packed, dst));
  EXPECT_EQ(cv::norm(dst, roi, cv::NORM_INF), 0.0);  // identity at pixel centres is exact
  auto tight = packMap(id, roi.size());
  ASSERT_TRUE(tight);
  EXPECT_EQ(remapRgba(roi, *tight, dst).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(packMap(id, {1, 5}).error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::render
