// Tests for pipelines/tracking/constellation_pose and stereo_position on synthetic
// views: LEDs about 6 cm apart at 2 m, blob noise 0.1 px (bound: <= 2 mm RMS).
//
// Theoretical bound (first order, positionCovariance): depth from one camera comes
// from the constellation's apparent size, sigma_z ~ z^2 sigma_px / (f r sqrt(n)),
// which for r ~ 4 cm, n = 5, z = 2 m, f = 1000 px is ~4 mm, so a single f = 1000 px
// camera cannot reach 2 mm; the test computes the bound and uses f = 4000 px (a
// ~17 deg lens on a 1280 px sensor) for one camera, and two f = 1000 px cameras 0.5 m
// apart (sigma_z ~ z^2 sqrt(2) sigma_px / (f b) ~ 1.1 mm per LED) for triangulation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "tracking/constellation_pose.hpp"
#include "tracking/stereo_position.hpp"

namespace procam::tracking {
namespace {

// Asymmetric, non-coplanar cap constellation (m, constellation frame, origin between
// the eyes); neighbouring LEDs ~6 cm apart.
const Points3 kLeds = {Vec3(-0.06, 0, 0), Vec3(0, 0, 0.0), Vec3(0.06, 0, 0), Vec3(0, -0.06, 0.02),
                       Vec3(0.03, -0.05, -0.03)};

geom::CameraModel makeCamera(double f, const Vec3& eye, const Vec3& target) {
  geom::CameraModel c;
  c.K = {f, f, 639.5, 511.5, 0};
  c.width = 1280;
  c.height = 1024;
  c.pose = geom::Pose::lookAt(eye, target, Vec3(0, 1, 0));
  return c;
}

struct Head {
  Mat3 R;  // constellation -> world
  Vec3 t;  // origin, world
  Vec3 led(int i) const { return R * kLeds[static_cast<size_t>(i)] + t; }
};

Head randomHead(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  // Facing the cameras (-z towards them) within +-25 deg, 2 m away.
  const Mat3 R = (Eigen::AngleAxisd(0.45 * u(rng), Vec3::UnitY()) *
                  Eigen::AngleAxisd(0.45 * u(rng), Vec3::UnitX()) *
                  Eigen::AngleAxisd(0.3 * u(rng), Vec3::UnitZ()))
                     .toRotationMatrix();
  return Head{R, Vec3(0.1 * u(rng), 0.1 * u(rng), 2.0 + 0.05 * u(rng))};
}

Points2 observe(const geom::CameraModel& cam, const Head& h, double sigma, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, sigma);
  Points2 px;
  for (int i = 0; i < static_cast<int>(kLeds.size()); ++i) {
    auto p = cam.project(h.led(i));
    px.push_back(*p + Vec2(n(rng), n(rng)));
  }
  return px;
}

// Cameras at the world origin looking along +z towards the viewer 2 m away.
double singleCameraBound(double f) {
  const geom::CameraModel cam = makeCamera(f, Vec3::Zero(), Vec3(0, 0, 2));
  geom::Pose head_in_cam;
  head_in_cam.t = cam.pose.toDevice(Vec3(0, 0, 2));
  head_in_cam.R = cam.pose.R * Eigen::AngleAxisd(M_PI, Vec3::UnitY()).toRotationMatrix();
  return std::sqrt(positionCovariance(cam.K, head_in_cam, kLeds, 0.1).trace());
}

// The head-position bound (<= 2 mm RMS) and agreement of the reported covariance with the
// observed scatter (>= 60 trials: the RMS is known to ~10 %, so +-30 %).
void expectWithinBudget(double sum_sq, double sum_trace, int trials) {
  const double rms = std::sqrt(sum_sq / trials), predicted = std::sqrt(sum_trace / trials);
  std::printf("position RMS %.2f mm, predicted %.2f mm\n", rms * 1e3, predicted * 1e3);
  EXPECT_LE(rms, 2e-3);
  EXPECT_NEAR(rms / predicted, 1.0, 0.3);
}

TEST(ConstellationPose, TheoreticalBoundDecidesTheLens) {
  std::printf("bound f=1000: %.2f mm, f=4000: %.2f mm\n", singleCameraBound(1000) * 1e3,
              singleCameraBound(4000) * 1e3);
  EXPECT_GT(singleCameraBound(1000), 2e-3);  // f = 1000 px cannot meet 2 mm at 2 m
  EXPECT_LT(singleCameraBound(4000), 1.5e-3);
}

TEST(ConstellationPose, SingleCameraMeetsTwoMillimetresWithALongLens) {
  std::mt19937_64 rng(11);
  const geom::CameraModel cam = makeCamera(4000, Vec3::Zero(), Vec3(0, 0, 2));
  double sq = 0, predicted = 0;
  const int trials = 60;
  for (int k = 0; k < trials; ++k) {
    Head h = randomHead(rng);
    h.R = h.R * Eigen::AngleAxisd(M_PI, Vec3::UnitY()).toRotationMatrix();  // LEDs face -z
    Points2 blobs = observe(cam, h, 0.1, rng);
    std::shuffle(blobs.begin(), blobs.end(), rng);  // the matcher must find the order
    auto pose = estimateConstellationPose(cam, kLeds, blobs, {});
    ASSERT_TRUE(pose) << pose.error().message;
    EXPECT_EQ(pose->matched, 5);
    for (int i = 0; i < 5; ++i) {
      const int b = pose->blob_of_led[static_cast<size_t>(i)];
      ASSERT_GE(b, 0);
      EXPECT_LT((blobs[static_cast<size_t>(b)] - *cam.project(h.led(i))).norm(), 1.0);
    }
    sq += (pose->position_world - h.t).squaredNorm();
    predicted += pose->covariance_world.trace();
  }
  expectWithinBudget(sq, predicted, trials);
}

TEST(ConstellationPose, PreviousPoseShortcutsTheSearch) {
  std::mt19937_64 rng(13);
  const geom::CameraModel cam = makeCamera(4000, Vec3::Zero(), Vec3(0, 0, 2));
  Head h = randomHead(rng);
  h.R = h.R * Eigen::AngleAxisd(M_PI, Vec3::UnitY()).toRotationMatrix();
  auto first = estimateConstellationPose(cam, kLeds, observe(cam, h, 0.1, rng), {});
  ASSERT_TRUE(first) << first.error().message;
  // One frame later: 5 mm and 1 degree of head motion.
  h.t += Vec3(0.004, -0.003, 0.0);
  h.R = Eigen::AngleAxisd(0.0175, Vec3::UnitY()).toRotationMatrix() * h.R;
  Points2 blobs = observe(cam, h, 0.1, rng);
  std::shuffle(blobs.begin(), blobs.end(), rng);
  auto searched = estimateConstellationPose(cam, kLeds, blobs, {});
  auto tracked = estimateConstellationPose(cam, kLeds, blobs, {}, first->pose);
  ASSERT_TRUE(searched && tracked);
  EXPECT_EQ(tracked->blob_of_led, searched->blob_of_led);
  EXPECT_LT((tracked->position_world - searched->position_world).norm(), 1e-6);
  // A stale pose (head turned 90 degrees) falls back to the search.
  geom::Pose stale = first->pose;
  stale.R = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()).toRotationMatrix() * stale.R;
  auto recovered = estimateConstellationPose(cam, kLeds, blobs, {}, stale);
  ASSERT_TRUE(recovered);
  EXPECT_EQ(recovered->blob_of_led, searched->blob_of_led);
}

TEST(ConstellationPose, ExtraBlobAndMissingLedAreHandled) {
  std::mt19937_64 rng(12);
  const geom::CameraModel cam = makeCamera(4000, Vec3::Zero(), Vec3(0, 0, 2));
  Head h = randomHead(rng);
  h.R = h.R * Eigen::AngleAxisd(M_PI, Vec3::UnitY()).toRotationMatrix();
  Points2 blobs = observe(cam, h, 0.1, rng);
  blobs.erase(blobs.begin() + 1);       // LED 1 occluded
  blobs.push_back(Vec2(300.2, 700.9));  // a reflection
  auto pose = estimateConstellationPose(cam, kLeds, blobs, {});
  ASSERT_TRUE(pose) << pose.error().message;
  EXPECT_EQ(pose->matched, 4);
  EXPECT_EQ(pose->blob_of_led[1], -1);
  EXPECT_LT((pose->position_world - h.t).norm(), 5e-3);

  // Random blobs only: no assignment passes the gate.
  Points2 junk = {Vec2(100, 100), Vec2(900, 120), Vec2(500, 800), Vec2(130, 640), Vec2(700, 300)};
  EXPECT_EQ(estimateConstellationPose(cam, kLeds, junk, {}).error().code, ErrorCode::kNotFound);
  EXPECT_EQ(estimateConstellationPose(cam, kLeds, Points2(junk.begin(), junk.begin() + 3), {})
                .error()
                .code,
            ErrorCode::kTooFewPoints);
}

TEST(StereoPosition, TwoShortLensCamerasMeetTwoMillimetres) {
  std::mt19937_64 rng(21);
  const Vec3 target(0, 0, 2);
  const std::vector<geom::CameraModel> cams = {makeCamera(1000, Vec3(-0.25, 0, 0), target),
                                               makeCamera(1000, Vec3(0.25, 0, 0), target)};
  double sq = 0, predicted = 0;
  const int trials = 200;
  for (int k = 0; k < trials; ++k) {
    Head h = randomHead(rng);
    h.R = h.R * Eigen::AngleAxisd(M_PI, Vec3::UnitY()).toRotationMatrix();
    const Points2 a = observe(cams[0], h, 0.1, rng), b = observe(cams[1], h, 0.1, rng);
    std::vector<TriangulatedPoint> leds;
    for (size_t i = 0; i < kLeds.size(); ++i) {
      const Points2 px = {a[i], b[i]};
      auto p = triangulateLed(cams, px, 0.1);
      ASSERT_TRUE(p) << p.error().message;
      leds.push_back(*p);
    }
    auto fit = fitConstellation(kLeds, leds);
    ASSERT_TRUE(fit) << fit.error().message;
    sq += (fit->position - h.t).squaredNorm();
    predicted += fit->covariance.trace();
  }
  expectWithinBudget(sq, predicted, trials);
}

TEST(StereoPosition, OneViewIsTooFew) {
  const std::vector<geom::CameraModel> one = {makeCamera(1000, Vec3::Zero(), Vec3(0, 0, 2))};
  const Points2 px = {Vec2(640, 512)};
  EXPECT_EQ(triangulateLed(one, px, 0.1).error().code, ErrorCode::kTooFewPoints);
}

}  // namespace
}  // namespace procam::tracking
