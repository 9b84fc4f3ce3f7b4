// The direct homography warp against the double-precision bilinear specification at the
// exact (double) source coordinates, its kernels against each other, and against the
// packed-map path.
#include <gtest/gtest.h>

#include "render/bilinear.hpp"
#include "render/packed_map.hpp"
#include "render/warp_homography.hpp"
#include "render/warp_map.hpp"
#include "render_test_images.hpp"

namespace procam::render {
namespace {

// A keystone-like H: the source lands on an oblique quadrilateral that leaves black
// margins and reaches past the output on one side, so the footprint edges are crossed.
Mat3 obliqueH() {
  Mat3 H;
  H << 0.93, 0.11, 31, -0.06, 1.02, 17, 4e-4, -2.2e-4, 1;
  return H;
}

// Worst |out - exact| over pixels whose exact source point is at least `margin` px inside
// the footprint (closer ones may fall either way in float); pixels clearly outside must
// be transparent black.
double worstAgainstSpecification(const cv::Mat& img, const Mat3& H, const cv::Mat& out,
                                 double margin) {
  const Mat3 Hinv = H.inverse();
  double worst = 0;
  for (int y = 0; y < out.rows; ++y) {
    for (int x = 0; x < out.cols; ++x) {
      const Vec3 p = Hinv * Vec3(x, y, 1);
      const double sx = p.x() / p.z(), sy = p.y() / p.z();
      const bool inside = p.z() > 0 &&
                          insideFootprint(sx + margin, sy + margin, img.cols, img.rows) &&
                          insideFootprint(sx - margin, sy - margin, img.cols, img.rows);
      const bool outside =
          p.z() <= 0 || (!insideFootprint(sx + margin, sy + margin, img.cols, img.rows) &&
                         !insideFootprint(sx - margin, sy - margin, img.cols, img.rows));
      const cv::Vec4b v = out.at<cv::Vec4b>(y, x);
      if (outside) {
        EXPECT_EQ(v, cv::Vec4b(0, 0, 0, 0)) << x << "," << y;
      } else if (inside) {
        const cv::Vec4d e = sampleBilinear(img, sx, sy);
        for (int c = 0; c < 4; ++c) worst = std::max(worst, std::abs(v[c] - e[c]));
      }
    }
  }
  return worst;
}

// Warps img into an image of out_size through obliqueH(): worstAgainstSpecification.
double warpedError(const cv::Mat& img, cv::Size out_size) {
  auto warp = makeHomographyWarp(obliqueH(), out_size, img.size());
  EXPECT_TRUE(warp);
  cv::Mat out;
  EXPECT_TRUE(warp && warpHomographyRgba(img, *warp, out));
  return out.empty() ? 1e9 : worstAgainstSpecification(img, obliqueH(), out, 1e-3);
}

TEST(WarpHomography, WithinTheQuantisationBoundOfTheDoubleSpecification) {
  // Position error <= 1/256 px (quantisation) + 1e-3 px (float evaluation) per axis;
  // one rounding: |out - exact| <= (Gx + Gy) (1/256 + 1e-3) + 1/2, G <= 255 per axis.
  EXPECT_LE(warpedError(test::randomImage({157, 123}, 21), {173, 141}),
            2 * 255 * (1.0 / 256 + 1e-3) + 0.5);
}

TEST(WarpHomography, SmoothContentStaysWithinOneCodeValue) {
  // G = 127.5 * 0.05 per axis: 2 * 6.375 * (1/256 + 1e-3) + 1/2 < 0.57.
  EXPECT_LE(warpedError(test::smoothImage({211, 167}, 0.05, 0.05), {240, 180}),
            2 * 6.375 * (1.0 / 256 + 1e-3) + 0.5);
}

TEST(WarpHomography, KernelsAgreeBitForBit) {
  // Width 301: the AVX2 kernel also runs its scalar tail.
  const cv::Mat img = test::randomImage({333, 211}, 22);
  auto warp = makeHomographyWarp(obliqueH(), {301, 199}, img.size());
  ASSERT_TRUE(warp);
  cv::Mat best, sse2, scalar;
  ASSERT_TRUE(warpHomographyRgba(img, *warp, best, RemapKernel::kBest));
  ASSERT_TRUE(warpHomographyRgba(img, *warp, sse2, RemapKernel::kSse2));
  ASSERT_TRUE(warpHomographyRgba(img, *warp, scalar, RemapKernel::kScalar));
  EXPECT_EQ(cv::norm(best, scalar, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(sse2, scalar, cv::NORM_INF), 0.0);
}

TEST(WarpHomography, AgreesWithThePackedMapPath) {
  // Both quantise to 1/128 px; float and double coordinates can round a tie differently,
  // which moves one weight by 1/128: at most 2 * 255 / 128 + 1 code values, rarely.
  const cv::Mat img = test::randomImage({320, 240}, 23);
  const cv::Size out_size(352, 260);
  auto warp = makeHomographyWarp(obliqueH(), out_size, img.size());
  auto map = homographyMap(obliqueH(), out_size);
  ASSERT_TRUE(warp && map);
  auto packed = packMap(*map, img.size());
  ASSERT_TRUE(packed);
  cv::Mat direct, mapped;
  ASSERT_TRUE(warpHomographyRgba(img, *warp, direct));
  ASSERT_TRUE(remapRgba(img, *packed, mapped));
  cv::Mat diff;
  cv::absdiff(direct, mapped, diff);
  EXPECT_LE(cv::norm(diff, cv::NORM_INF), 2 * 255.0 / 128 + 1);
  EXPECT_LE(cv::mean(diff)[0], 0.05);
}

TEST(WarpHomography, HonoursRowStepsAndRejectsBadInput) {
  const cv::Mat big = test::randomImage({64, 48}, 24);
  const cv::Mat roi = big(cv::Rect(5, 3, 40, 30));
  auto id = makeHomographyWarp(Mat3::Identity(), roi.size(), roi.size());
  ASSERT_TRUE(id);
  cv::Mat out;
  ASSERT_TRUE(warpHomographyRgba(roi, *id, out));
  EXPECT_EQ(cv::norm(out, roi, cv::NORM_INF), 0.0);  // pixel centres map to themselves
  EXPECT_EQ(warpHomographyRgba(big, *id, out).error().code, ErrorCode::kInvalidInput);
  Mat3 singular = Mat3::Identity();
  singular(2, 2) = 0;
  singular(2, 0) = 0;
  singular.row(1) = singular.row(0);
  EXPECT_EQ(makeHomographyWarp(singular, {8, 8}, {8, 8}).error().code, ErrorCode::kDegenerate);
  EXPECT_EQ(makeHomographyWarp(Mat3::Identity(), {8, 8}, {1, 8}).error().code,
            ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::render
