// Intensity feathering ([Raskar02] eq. 4.3) on a 2x2 wall.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "blend/feather.hpp"
#include "wall_tiles.hpp"

namespace procam::blend {
namespace {

struct Fixture {
  std::vector<FeatherTile> tiles;
  std::vector<cv::Mat> weights;
  keystone::AxisRect display;
};

Fixture feathered() {
  Fixture f;
  const auto ps = testing::twoByTwo();
  auto d = solveTiledDisplay(testing::tilesOf(ps), 1920, 1080);
  EXPECT_TRUE(d);
  f.display = d->rect;
  for (std::size_t t = 0; t < ps.size(); ++t)
    f.tiles.push_back(
        {d->footprints[t], d->plane_to_framebuffer[t], ps[t].tile.width, ps[t].tile.height});
  auto w = featherWeights(f.tiles);
  EXPECT_TRUE(w);
  if (w) f.weights = *w;
  return f;
}

double bilinear(const cv::Mat& w, const Vec2& p) {
  cv::Mat out;
  cv::Mat mx(1, 1, CV_32F, cv::Scalar(p.x())), my(1, 1, CV_32F, cv::Scalar(p.y()));
  cv::remap(w, out, mx, my, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
  return out.at<float>(0, 0);
}

// At every 17th pixel centre of every tile, the weights of all tiles at that wall point
// add up to one: exactly at the tile's own pixel, bilinearly interpolated in the others
// (their weights are linear in wall distance over a few pixels: interpolation adds
// at most a few 1e-4).
TEST(Feather, WeightsOfEveryWallPointSumToOne) {
  const Fixture f = feathered();
  ASSERT_EQ(f.weights.size(), 4u);
  double worst = 0;
  int overlapping = 0;
  for (std::size_t m = 0; m < f.tiles.size(); ++m) {
    const Mat3 to_wall = f.tiles[m].plane_to_framebuffer.inverse();
    for (int y = 8; y < f.tiles[m].height - 8; y += 17) {
      for (int x = 8; x < f.tiles[m].width - 8; x += 17) {
        const Vec3 wall = to_wall * Vec3(x, y, 1);
        double sum = f.weights[m].at<float>(y, x);
        int seen = 1;
        for (std::size_t i = 0; i < f.tiles.size(); ++i) {
          if (i == m) continue;
          const Vec2 q = (f.tiles[i].plane_to_framebuffer * wall).hnormalized();
          if (q.x() < 0 || q.y() < 0 || q.x() > f.tiles[i].width - 1 ||
              q.y() > f.tiles[i].height - 1)
            continue;
          sum += bilinear(f.weights[i], q);
          ++seen;
        }
        // Points within a pixel of another image's edge see it only partly: skip.
        bool near_edge = false;
        for (std::size_t i = 0; i < f.tiles.size(); ++i) {
          const Vec2 q = (f.tiles[i].plane_to_framebuffer * wall).hnormalized();
          near_edge = near_edge || (std::abs(q.x() + 0.5) < 2 || std::abs(q.y() + 0.5) < 2 ||
                                    std::abs(q.x() - f.tiles[i].width + 0.5) < 2 ||
                                    std::abs(q.y() - f.tiles[i].height + 0.5) < 2);
        }
        if (near_edge) continue;
        overlapping += seen > 1;
        worst = std::max(worst, std::abs(sum - 1));
      }
    }
  }
  std::printf("[ figures  ] %d overlap samples, worst |sum - 1| %.2e\n", overlapping, worst);
  EXPECT_GT(overlapping, 1000);
  EXPECT_LT(worst, 2e-3);
}

// Eq. 4.3 weighs by the distance to the image's own edge over the sum: a pixel lit by
// its projector alone has weight 1 (up to the display's outer edge), and where another
// image begins the weight falls smoothly to 0 at its own edge. Neighbouring pixels
// change by a ramp's slope, not by jumps: overlaps of 0.25-0.3 m (190-230 px) give
// 1/190 per pixel, several times that where the ramps of four images cross (measured:
// 1/29), while a seam would step by a good part of the weight; 0.05 is allowed. Not
// within 10 % of the display's edge, where two image edges meet at the union's
// boundary: both distances there are a few millimetres and the weights turn within a
// few pixels (continuously: the sums stay one). The pixel at a corner inside another
// image is half a pixel and up to half a raster cell (1.2 px) from its edge: weight
// under 0.02 of a 190-pixel ramp.
TEST(Feather, WeightsAreSmoothRampsToTheEdges) {
  const Fixture f = feathered();
  // Tiles: 0 top left, 1 top right, 2 bottom left, 3 bottom right.
  const cv::Mat& w0 = f.weights[0];
  EXPECT_FLOAT_EQ(w0.at<float>(0, 0), 1.f);
  EXPECT_LT(w0.at<float>(w0.rows - 1, w0.cols - 1), 0.02);
  EXPECT_LT(f.weights[3].at<float>(0, 0), 0.02);
  for (std::size_t m = 0; m < f.tiles.size(); ++m) {
    const cv::Mat& w = f.weights[m];
    double lo, hi;
    cv::minMaxLoc(w, &lo, &hi);
    EXPECT_GE(lo, 0.0);
    EXPECT_NEAR(hi, 1.0, 1e-6) << "tile " << m << " has a region of its own";
    const Mat3 to_wall = f.tiles[m].plane_to_framebuffer.inverse();
    double steepest = 0;
    for (int y = 0; y + 1 < w.rows; ++y) {
      for (int x = 0; x + 1 < w.cols; ++x) {
        const Vec2 p = (to_wall * Vec3(x, y, 1)).hnormalized() - f.display.centre;
        if (std::abs(p.x()) > 0.9 * f.display.half_width ||
            std::abs(p.y()) > 0.9 * f.display.half_height)
          continue;
        steepest = std::max({steepest, double(std::abs(w.at<float>(y, x + 1) - w.at<float>(y, x))),
                             double(std::abs(w.at<float>(y + 1, x) - w.at<float>(y, x)))});
      }
    }
    std::printf("[ figures  ] tile %zu: steepest step inside 90 %% of the display %.4f\n", m,
                steepest);
    EXPECT_LT(steepest, 0.05);
  }
  const cv::Mat a = alphaMask(w0);
  EXPECT_EQ(a.type(), CV_8UC1);
  EXPECT_EQ(a.at<uint8_t>(0, 0), 255);
  EXPECT_LE(a.at<uint8_t>(w0.rows - 1, w0.cols - 1), 5);
}

TEST(Feather, BadTilesAreRefused) {
  EXPECT_FALSE(featherWeights(std::vector<FeatherTile>{}));
  FeatherTile t{};
  t.plane_to_framebuffer = Mat3::Zero();
  t.width = t.height = 10;
  EXPECT_EQ(featherWeights(std::vector<FeatherTile>{t}).error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::blend
