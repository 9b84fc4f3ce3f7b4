// The dot grid a handheld projector shows for its camera to find the wall by
// (keystone/dot_grid.hpp), on synthetic camera images: Gaussian blobs where the camera
// sees each dot, a floor that takes the lowest rows, and noise.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>

#include "keystone/display_error.hpp"
#include "keystone/dot_grid.hpp"
#include "keystone/keystone_solver.hpp"
#include "keystone/orientation.hpp"

namespace procam::keystone {
namespace {

// The handheld scene's pair: a 1280 x 720 projector (fx 1400) and a 640 x 480 camera
// (fx 560) 6 cm to the right of the lens, toed in by 3 degrees.
struct Pair {
  geom::Intrinsics projector{1400, 1400, 639.5, 359.5, 0};
  geom::CameraModel camera;
  Pair() {
    camera.K = geom::Intrinsics{560, 560, 319.5, 239.5, 0};
    camera.width = 640;
    camera.height = 480;
    camera.pose.R = Eigen::AngleAxisd(3 * M_PI / 180, Vec3::UnitY()).toRotationMatrix();
    camera.pose.t = -camera.pose.R * Vec3(0.06, 0, 0);
  }
};

struct Plane {
  Vec3 n;  // unit, projector frame, facing away from the projector
  double d;
};

// The camera image of `grid` when each projector ray meets the nearer of `planes`: a
// Gaussian of sigma 1.2 px and 100 codes per dot on a background of 10, plus white
// noise (the mean of a few frames of an 8-bit camera).
cv::Mat render(const Pair& pair, const DotGrid& grid, const std::vector<Plane>& planes,
               double noise, std::vector<bool>* on_first = nullptr) {
  cv::Mat image(pair.camera.height, pair.camera.width, CV_32F, cv::Scalar(10));
  const Mat3 Kp_inv = pair.projector.matrix().inverse();
  constexpr double kSigma = 1.2;
  for (const Vec2& c : grid.centres) {
    const Vec3 ray = Kp_inv * c.homogeneous();
    double t = INFINITY;
    std::size_t hit = 0;
    for (std::size_t i = 0; i < planes.size(); ++i) {
      const double s = planes[i].n.dot(ray);
      if (s > 0 && planes[i].d / s < t) t = planes[i].d / s, hit = i;
    }
    if (on_first) on_first->push_back(hit == 0);
    const auto q = pair.camera.project(ray * t);
    if (!q) continue;
    for (int y = int(q->y()) - 5; y <= int(q->y()) + 5; ++y) {
      for (int x = int(q->x()) - 5; x <= int(q->x()) + 5; ++x) {
        if (x < 0 || y < 0 || x >= image.cols || y >= image.rows) continue;
        const double r2 = (Vec2(x, y) - *q).squaredNorm();
        image.at<float>(y, x) += float(100 * std::exp(-r2 / (2 * kSigma * kSigma)));
      }
    }
  }
  std::mt19937 rng(7);
  std::normal_distribution<float> n(0, float(noise));
  for (auto it = image.begin<float>(); it != image.end<float>(); ++it) *it += n(rng);
  return image;
}

// The keystone corner error (framebuffer px, content the framebuffer's size) of the
// orientation fused from the exact gravity and the wall normal `found`, judged with the
// true orientation: the camera's share of procamd's keystone bound (corner <= 0.5 px).
double cornerError(const geom::Intrinsics& K, const Mat3& R_true, const Vec3& found) {
  const Vec3 down = R_true * Vec3(0, 0, -1);
  auto fused = fuseOrientation(down, found);
  EXPECT_TRUE(fused);
  if (!fused) return 1e9;
  KeystoneProblem p;
  p.K = K;
  p.width = p.content_width = 1280;
  p.height = p.content_height = 720;
  p.R = fused->R;
  auto est = solveKeystone(p);
  p.R = R_true;
  auto truth = solveKeystone(p);
  EXPECT_TRUE(est && truth);
  if (!est || !truth) return 1e9;
  double worst = displayError(K, R_true, est->corners).max_corner_px;
  for (int i = 0; i < 4; ++i) worst = std::max(worst, (est->corners[i] - truth->corners[i]).norm());
  return worst;
}

TEST(DotGrid, LayoutScalesWithTheFramebuffer) {
  auto big = makeDotGrid(1920, 1080);
  auto small = makeDotGrid(1280, 720);
  ASSERT_TRUE(big && small);
  EXPECT_EQ(big->centres.size(), 39u * 21u);
  EXPECT_EQ(small->centres.size(), 39u * 21u);
  EXPECT_EQ(big->centres.front(), Vec2(105, 90));
  EXPECT_EQ(small->centres.front(), Vec2(70, 60));
  EXPECT_DOUBLE_EQ(small->sigma_px, 2.0);
  EXPECT_EQ(small->image.at<std::uint8_t>(60, 70), 255);
  EXPECT_EQ(small->image.at<std::uint8_t>(60, 85), 0);  // between two dots
  EXPECT_EQ(makeDotGrid(32, 720).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(makeDotGrid(1280, 20000).error().code, ErrorCode::kInvalidInput);
}

TEST(DotGrid, WallFoundWithinTheKeystoneBound) {
  // The wall 2.5 m from the lens, the projector turned to the extremes its keystone is
  // specified for; noise of the mean of a few 8-bit frames.
  const Pair pair;
  auto grid = makeDotGrid(1280, 720);
  ASSERT_TRUE(grid);
  for (auto [yaw, pitch, roll] :
       {std::tuple{0.0, 0.0, 0.0}, {30.0, 45.0, 20.0}, {-30.0, -45.0, -20.0}, {20.0, -10.0, 5.0}}) {
    const Mat3 R = rotationFromAngles({pitch * M_PI / 180, roll * M_PI / 180, yaw * M_PI / 180});
    const Vec3 n = R * Vec3(0, 1, 0);  // the wall frame's +Y points into the wall
    const cv::Mat image = render(pair, *grid, {{n, 2.5}}, 0.3);
    auto wall = wallFromDots(*grid, image, pair.projector, pair.camera);
    ASSERT_TRUE(wall) << wall.error().message;
    const double angle = std::acos(std::min(1.0, wall->plane.normal.dot(n)));
    const double corner = cornerError(pair.projector, R, wall->plane.normal);
    std::printf(
        "yaw %g pitch %g roll %g: %zu of %zu dots used, normal off by %.3f mrad, "
        "distance %.4f m, %.3f px RMS: keystone corner %.3f px\n",
        yaw, pitch, roll, wall->matched, wall->shown, angle * 1e3, wall->plane.distance,
        wall->plane.rms, corner);
    EXPECT_LE(corner, 0.5);
    EXPECT_NEAR(wall->plane.distance, 2.5, 0.025);
    EXPECT_GT(wall->matched, wall->shown * 9 / 10);
  }
}

TEST(DotGrid, DotsOnAnotherSurfaceAreLeftOut) {
  // A floor takes the lowest rows (a quarter of the dots): the wall is still found.
  const Pair pair;
  auto grid = makeDotGrid(1280, 720);
  ASSERT_TRUE(grid);
  const Mat3 R = rotationFromAngles({5 * M_PI / 180, 0, 15 * M_PI / 180});
  const Vec3 n = R * Vec3(0, 1, 0);
  std::vector<bool> on_wall;
  const cv::Mat image =
      render(pair, *grid, {{n, 2.5}, {Vec3(0, 1, 0.2).normalized(), 0.8}}, 0.3, &on_wall);
  const auto floor = std::count(on_wall.begin(), on_wall.end(), false);
  ASSERT_GT(floor, long(on_wall.size() / 6));
  auto wall = wallFromDots(*grid, image, pair.projector, pair.camera);
  ASSERT_TRUE(wall) << wall.error().message;
  const double corner = cornerError(pair.projector, R, wall->plane.normal);
  std::printf("%ld of %zu dots on the floor; %zu used; keystone corner %.3f px\n", floor,
              on_wall.size(), wall->matched, corner);
  // The floor's dots where it meets the wall lie on both within the noise; none beyond.
  EXPECT_LE(wall->matched, on_wall.size() - std::size_t(floor) + std::size_t(floor) / 20);
  EXPECT_GT(wall->matched, (on_wall.size() - std::size_t(floor)) * 9 / 10);
  EXPECT_LE(corner, 0.5);
}

TEST(DotGrid, TypedErrors) {
  const Pair pair;
  auto grid = makeDotGrid(1280, 720);
  ASSERT_TRUE(grid);
  const cv::Mat blank(480, 640, CV_32F, cv::Scalar(10));
  EXPECT_EQ(wallFromDots(*grid, blank, pair.projector, pair.camera).error().code,
            ErrorCode::kTooFewPoints);
  EXPECT_EQ(
      wallFromDots(*grid, cv::Mat(480, 640, CV_8U, cv::Scalar(0)), pair.projector, pair.camera)
          .error()
          .code,
      ErrorCode::kInvalidInput);
  WallFromDotsOptions bad;
  bad.gate = 0;
  EXPECT_EQ(wallFromDots(*grid, blank, pair.projector, pair.camera, bad).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_TRUE(detectDots(cv::Mat()).empty());
}

}  // namespace
}  // namespace procam::keystone
