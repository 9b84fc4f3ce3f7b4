// Bilinear sampling convention, warp-map construction (homography, grid, composition)
// and the OpenGL convention conversion.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "render/bilinear.hpp"
#include "render/gl_conventions.hpp"
#include "render/warp_map.hpp"
#include "render_test_images.hpp"

namespace procam::render {
namespace {

TEST(Bilinear, PixelCentresAreExactAndMidpointsAverage) {
  const cv::Mat img = test::randomImage({7, 5}, 1);
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 7; ++x) {
      const cv::Vec4d s = sampleBilinear(img, x, y);
      for (int c = 0; c < 4; ++c) EXPECT_DOUBLE_EQ(s[c], img.at<cv::Vec4b>(y, x)[c]);
    }
  }
  const cv::Vec4d mid = sampleBilinear(img, 2.5, 3.5);
  for (int c = 0; c < 4; ++c) {
    const double expect = (img.at<cv::Vec4b>(3, 2)[c] + img.at<cv::Vec4b>(3, 3)[c] +
                           img.at<cv::Vec4b>(4, 2)[c] + img.at<cv::Vec4b>(4, 3)[c]) /
                          4.0;
    EXPECT_DOUBLE_EQ(mid[c], expect);
  }
}

TEST(Bilinear, FootprintIsHalfPixelAroundCentresAndClampsInside) {
  const cv::Mat img = test::randomImage({4, 3}, 2);
  // Inside the outer half pixel: the edge texel.
  EXPECT_EQ(sampleBilinear(img, -0.5, 0)[0], img.at<cv::Vec4b>(0, 0)[0]);
  EXPECT_EQ(sampleBilinear(img, 3.49, 2.49)[1], img.at<cv::Vec4b>(2, 3)[1]);
  // Outside the footprint: transparent black.
  EXPECT_EQ(sampleBilinear(img, -0.51, 1)[0], 0.0);
  EXPECT_EQ(sampleBilinear(img, 3.5, 1)[3], 0.0);
  EXPECT_EQ(sampleBilinear(img, 1, 2.5)[3], 0.0);
  EXPECT_EQ(sampleBilinear(img, NAN, 1)[3], 0.0);
}

TEST(GlConventions, PixelEdgesMapToNdcBoundsAndTexelCentres) {
  const int W = 640, H = 480;
  const auto fbo = glConventions(W, H, GlOrigin::kRow0AtGlBottom);
  const auto top = glConventions(W, H, GlOrigin::kRow0AtGlTop);
  const Vec4 left_top_edge = fbo.clip_from_pixel * Vec4(-0.5, -0.5, 0, 1);
  EXPECT_NEAR(left_top_edge.x(), -1, 1e-15);
  EXPECT_NEAR(left_top_edge.y(), -1, 1e-15);  // image row 0 at GL y = 0 (first row read back)
  const Vec4 right_bottom = fbo.clip_from_pixel * Vec4(W - 0.5, H - 0.5, 0, 1);
  EXPECT_NEAR(right_bottom.x(), 1, 1e-15);
  EXPECT_NEAR(right_bottom.y(), 1, 1e-15);
  EXPECT_NEAR((top.clip_from_pixel * Vec4(0, -0.5, 0, 1)).y(), 1, 1e-15);  // top of screen
  // Homogeneous input: scaling by w changes nothing after the division.
  const Vec4 h = fbo.clip_from_pixel * Vec4(3 * 10.0, 3 * 20.0, 3 * 0.5, 3);
  EXPECT_NEAR(h.x() / h.w(), (2 * 10.0 + 1) / W - 1, 1e-15);
  EXPECT_NEAR(h.z() / h.w(), 0.5, 1e-15);
  const Vec3 t = fbo.tex_from_pixel * Vec3(0, H - 1, 1);
  EXPECT_NEAR(t.x(), 0.5 / W, 1e-15);
  EXPECT_NEAR(t.y(), 1 - 0.5 / H, 1e-15);
}

Mat3 randomHomography(std::mt19937& rng, cv::Size out, cv::Size src) {
  // Source corners to a perturbed quadrilateral inside the output.
  std::uniform_real_distribution<double> j(-0.15, 0.15);
  const double sw = src.width, sh = src.height, ow = out.width, oh = out.height;
  cv::Point2f s[4] = {{0, 0}, {float(sw), 0}, {float(sw), float(sh)}, {0, float(sh)}};
  cv::Point2f d[4];
  const double base[4][2] = {{0.1, 0.1}, {0.9, 0.1}, {0.9, 0.9}, {0.1, 0.9}};
  for (int k = 0; k < 4; ++k) {
    d[k] = cv::Point2f(float((base[k][0] + j(rng)) * ow), float((base[k][1] + j(rng)) * oh));
  }
  // Solve the 8x8 system directly (independent of the code under test).
  Eigen::Matrix<double, 8, 8> A;
  Eigen::Matrix<double, 8, 1> b;
  for (int k = 0; k < 4; ++k) {
    const double x = s[k].x, y = s[k].y, u = d[k].x, v = d[k].y;
    A.row(2 * k) << x, y, 1, 0, 0, 0, -u * x, -u * y;
    A.row(2 * k + 1) << 0, 0, 0, x, y, 1, -v * x, -v * y;
    b(2 * k) = u;
    b(2 * k + 1) = v;
  }
  const Eigen::Matrix<double, 8, 1> h = A.fullPivLu().solve(b);
  Mat3 H;
  H << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1;
  return H;
}

TEST(HomographyMap, Float32MapWithinHalfUlpOfDoubleMapping) {
  // Floats are allowed per pixel only with a bound: each entry must be the double
  // backward mapping rounded once to float (<= half an ulp, 1.2e-4 px below 4096).
  std::mt19937 rng(7);
  const cv::Size out(1920, 1080), src(1280, 720);
  for (int trial = 0; trial < 5; ++trial) {
    const Mat3 H = randomHomography(rng, out, src);
    auto map = homographyMap(H, out);
    ASSERT_TRUE(map);
    const Mat3 Hinv = H.inverse();
    double worst = 0;
    for (int y = 0; y < out.height; y += 7) {
      for (int x = 0; x < out.width; x += 5) {
        const Vec3 p = Hinv * Vec3(x, y, 1);
        const Vec2 s = p.hnormalized();
        const cv::Vec2f m = map->xy.at<cv::Vec2f>(y, x);
        const double ulp =
            std::nextafter(float(std::abs(s.x())), INFINITY) - float(std::abs(s.x()));
        worst = std::max(worst, std::abs(m[0] - s.x()) / ulp);
        const double ulpy =
            std::nextafter(float(std::abs(s.y())), INFINITY) - float(std::abs(s.y()));
        worst = std::max(worst, std::abs(m[1] - s.y()) / ulpy);
      }
    }
    EXPECT_LE(worst, 0.5 + 1e-4) << "trial " << trial;
  }
}

TEST(HomographyMap, SingularAndNonFiniteAreTypedErrors) {
  Mat3 S = Mat3::Zero();
  S(0, 0) = 1;
  S(1, 1) = 1;
  EXPECT_EQ(homographyMap(S, {10, 10}).error().code, ErrorCode::kDegenerate);
  Mat3 N = Mat3::Identity();
  N(0, 1) = NAN;
  EXPECT_EQ(homographyMap(N, {10, 10}).error().code, ErrorCode::kInvalidInput);
}

TEST(HomographyMap, PointsBehindTheLineAtInfinityAreOutside) {
  Mat3 H = Mat3::Identity();
  H(2, 0) = 0.01;  // backward map: w = 1 - 0.01 x, negative beyond x = 100
  auto map = homographyMap(H, {200, 4});
  ASSERT_TRUE(map);
  // Every entry stays finite.
  int outside = 0;
  for (int x = 0; x < 200; ++x) {
    const cv::Vec2f v = map->xy.at<cv::Vec2f>(1, x);
    ASSERT_TRUE(std::isfinite(v[0]) && std::isfinite(v[1]));
    outside += v[0] == kOutside;
  }
  EXPECT_GT(outside, 0);
}

TEST(GridMap, ReproducesAnAffineGridExactlyAndIsOutsideBeyondIt) {
  WarpGrid g;
  g.cols = 9;
  g.rows = 6;
  g.origin = Vec2(3, 2);
  g.step = Vec2(8, 8);
  const Eigen::Matrix2d A{{0.9, 0.1}, {-0.05, 1.1}};
  const Vec2 b(4.5, -2.25);
  for (int j = 0; j < g.rows; ++j)
    for (int i = 0; i < g.cols; ++i) g.source.push_back(A * g.node(i, j) + b);
  auto map = gridMap(g, {80, 50});
  ASSERT_TRUE(map);
  for (int y = 0; y < 50; ++y) {
    for (int x = 0; x < 80; ++x) {
      const cv::Vec2f m = map->xy.at<cv::Vec2f>(y, x);
      const bool inside = x >= 3 && y >= 2 && x <= 3 + 64 && y <= 2 + 40;
      if (!inside) {
        EXPECT_EQ(m[0], kOutside);
        continue;
      }
      const Vec2 e = A * Vec2(x, y) + b;
      EXPECT_NEAR(m[0], e.x(), 1e-4);
      EXPECT_NEAR(m[1], e.y(), 1e-4);
    }
  }
}

TEST(GridMap, IsPiecewiseLinearAlongTheCellDiagonal) {
  // One cell whose (1,1) node is displaced: pixels on the diagonal interpolate between
  // nodes (0,0) and (1,1) only; above/below it each triangle is affine.
  WarpGrid g;
  g.cols = 2;
  g.rows = 2;
  g.step = Vec2(10, 10);
  g.source = {Vec2(0, 0), Vec2(10, 0), Vec2(0, 10), Vec2(14, 12)};
  auto map = gridMap(g, {11, 11});
  ASSERT_TRUE(map);
  EXPECT_NEAR(map->xy.at<cv::Vec2f>(5, 5)[0], 7.0, 1e-5);
  EXPECT_NEAR(map->xy.at<cv::Vec2f>(5, 5)[1], 6.0, 1e-5);
  // Upper triangle (u >= v): nodes 00, 10, 11 -> at (8, 2): s = 00 + .8(10-00) + .2(11-10)
  EXPECT_NEAR(map->xy.at<cv::Vec2f>(2, 8)[0], 8 + 0.2 * 4, 1e-5);
  EXPECT_NEAR(map->xy.at<cv::Vec2f>(2, 8)[1], 0.2 * 12, 1e-5);
}

TEST(GridMap, TrianglesWithANodeNoSourceReachesAreNotDrawn) {
  // Node (1,0) of one cell is kOutside (its ray missed the surface): the upper triangle
  // (00, 10, 11) is outside; the lower one (00, 11, 01) is drawn as before. Interpolating
  // towards kOutside would have put content from -65536 next to the footprint's edge.
  WarpGrid g;
  g.cols = 2;
  g.rows = 2;
  g.step = Vec2(10, 10);
  g.source = {Vec2(0, 0), Vec2(kOutside, kOutside), Vec2(0, 10), Vec2(10, 10)};
  auto map = gridMap(g, {11, 11});
  ASSERT_TRUE(map);
  EXPECT_EQ(map->xy.at<cv::Vec2f>(2, 8)[0], kOutside);  // upper: x 8 >= y 2
  EXPECT_FALSE(gridSource(g, Vec2(8, 2)));
  EXPECT_NEAR(map->xy.at<cv::Vec2f>(8, 2)[0], 2.0, 1e-5);  // lower: x 2 < y 8
  EXPECT_NEAR(map->xy.at<cv::Vec2f>(8, 2)[1], 8.0, 1e-5);
  const auto s = gridSource(g, Vec2(2.5, 7.25));
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->x(), 2.5, 1e-12);
  EXPECT_NEAR(s->y(), 7.25, 1e-12);  // A grid gridMap refuses has no source anywhere (no read outside its nodes).
  WarpGrid thin = g;
  thin.cols = 1;
  EXPECT_FALSE(gridSource(thin, Vec2(0, 0)));
  thin = g;
  thin.source.pop_back();
  EXPECT_FALSE(gridSource(thin, Vec2(2.5, 7.25)));
}

TEST(ComposeMaps, EqualsTheAnalyticComposition) {
  Mat3 H;
  H << 1.1, 0.05, 12, -0.03, 0.95, 7, 1e-4, -5e-5, 1;
  auto first = homographyMap(H, {300, 200});
  ASSERT_TRUE(first);
  WarpGrid g;  // translation by (2.5, -1.25)
  g.cols = 2;
  g.rows = 2;
  g.step = Vec2(299, 199);
  g.source = {Vec2(2.5, -1.25), Vec2(301.5, -1.25), Vec2(2.5, 197.75), Vec2(301.5, 197.75)};
  auto second = gridMap(g, {300, 200});
  ASSERT_TRUE(second);
  auto both = composeMaps(*first, *second);
  ASSERT_TRUE(both);
  const Mat3 Hinv = H.inverse();
  for (int y = 10; y < 190; y += 9) {
    for (int x = 10; x < 290; x += 11) {
      const Vec2 e = (Hinv * Vec3(x + 2.5, y - 1.25, 1)).hnormalized();
      const cv::Vec2f m = both->xy.at<cv::Vec2f>(y, x);
      // Bilinear interpolation of a smooth map: error ~ curvature/8, tiny here.
      EXPECT_NEAR(m[0], e.x(), 2e-3);
      EXPECT_NEAR(m[1], e.y(), 2e-3);
    }
  }
}

}  // namespace
}  // namespace procam::render
