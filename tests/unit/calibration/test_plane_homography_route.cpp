// Route (b′) on synthetic decoded maps: a calibrated camera (with lens distortion)
// sees a projector light a wall whose plane is known; the decoded map holds, per
// camera pixel, the projector pixel that lights what it sees. The projector's
// collineation with the plane is judged where keystone needs it, at the corners of
// the projector's image: each is mapped onto the plane and reprojected through the
// true projector (projector pixels).
#include <gtest/gtest.h>

#include <random>

#include "calibration/plane_homography_route.hpp"
#include "plane_corners.hpp"
#include "structured_light/pattern_set.hpp"
#include "synthetic_rig.hpp"

using namespace procam;
using procam::testing::litPoint;
using procam::testing::planeThrough;

namespace {

const geom::Plane kWall =
    planeThrough(Vec3(0.0, 0.3, 0.5), Eigen::AngleAxisd(0.44, Vec3::UnitZ()) * Vec3(0, -1, 0));

sl::PatternSet patternSet(const geom::CameraModel& projector) {
  sl::PatternOptions o;
  o.width = projector.width;
  o.height = projector.height;
  o.mode = sl::Mode::kGrayPhase;
  o.phase_steps = 3;
  auto set = sl::makePatternSet(o);
  EXPECT_TRUE(set) << set.error().message;
  return *set;
}

// Per camera pixel, the projector pixel lighting the wall point it sees, plus
// Gaussian decoding noise of `sigma` projector pixels per axis.
sl::Decoded decodedMap(const geom::CameraModel& camera, const geom::CameraModel& projector,
                       const geom::Plane& plane, double sigma, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, sigma);
  sl::Decoded d;
  d.u = cv::Mat(camera.height, camera.width, CV_32F, cv::Scalar(-1));
  d.v = cv::Mat(camera.height, camera.width, CV_32F, cv::Scalar(-1));
  d.confidence = cv::Mat(camera.height, camera.width, CV_32F, cv::Scalar(0));
  d.flags = cv::Mat(camera.height, camera.width, CV_8U, cv::Scalar(sl::kShadow));
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      auto ray = camera.backproject(Vec2(x, y));
      if (!ray) continue;
      auto hit = geom::intersectPlane(*ray, plane);
      if (!hit) continue;
      auto p = projector.project(hit->point);
      if (!p || !projector.inImage(*p)) continue;
      d.u.at<float>(y, x) = static_cast<float>(p->x() + noise(rng));
      d.v.at<float>(y, x) = static_cast<float>(p->y() + noise(rng));
      d.confidence.at<float>(y, x) = 1;
      d.flags.at<std::uint8_t>(y, x) = 0;
      ++d.decoded;
    }
  return d;
}

sl::Decoded copyOf(const sl::Decoded& d) {
  sl::Decoded c = d;
  c.u = d.u.clone();
  c.v = d.v.clone();
  c.confidence = d.confidence.clone();
  c.flags = d.flags.clone();
  return c;
}

TEST(PlaneHomographyRoute, ExactMapGivesTheProjectorsCollineation) {
  const auto projector = procam::testing::squarePixelProjector();
  const auto camera = procam::testing::camera640();
  const auto set = patternSet(projector);
  const calib::DecodedView view{"cam", camera, decodedMap(camera, projector, kWall, 0)};
  auto r = calib::solvePlaneHomographyRoute(set, view, kWall);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_GT(r->coverage, 0.3);
  EXPECT_EQ(r->inliers, r->samples);
  // Exact maps, stored as float32 (1e-4 px at 1024): the sampler's local affine
  // fits and the rounding leave hundredths of a pixel at most.
  EXPECT_LT(r->rms_projector_px, 0.01);
  EXPECT_LT(procam::testing::planeCornerErrorPx(r->projector_to_plane, projector), 0.01);
  // The basis is upright (world +Z up), on the camera's side of the wall.
  const geom::PlaneBasis& b = r->projector_to_plane.basis;
  EXPECT_NEAR(b.u.z(), 0, 1e-12);
  EXPECT_GT(b.v.z(), 0);
  EXPECT_NEAR(std::abs(b.normal().dot(kWall.n)), 1, 1e-12);
  EXPECT_GT(b.normal().dot(camera.pose.center() - b.origin), 0);
  EXPECT_NEAR(kWall.signedDistance(b.origin), 0, 1e-9);
}

// Decoding noise at the Gray + phase bound (0.1 px RMS per axis) and a patch of
// wrong codes (an interreflection, 3 % of the image): RANSAC keeps the wrong nodes
// out, and the corners stay within the keystone bound (0.5 projector px).
TEST(PlaneHomographyRoute, NoiseAndWrongCodesStayWithinTheKeystoneBound) {
  const auto projector = procam::testing::squarePixelProjector();
  const auto camera = procam::testing::camera640();
  sl::Decoded d = decodedMap(camera, projector, kWall, 0.1, 3);
  const cv::Rect patch(300, 220, 40, 30);
  d.u(patch) += 37.0f;
  d.v(patch) -= 21.0f;
  const calib::DecodedView view{"cam", camera, d};
  auto r = calib::solvePlaneHomographyRoute(patternSet(projector), view, kWall);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_LT(r->inliers, r->samples);  // the patch's nodes were rejected
  EXPECT_LT(procam::testing::planeCornerErrorPx(r->projector_to_plane, projector), 0.5);
  std::printf("[ figures  ] corner %.4f px, RMS %.4f camera px, %.4f projector px, %zu of %zu\n",
              procam::testing::planeCornerErrorPx(r->projector_to_plane, projector),
              r->rms_camera_px, r->rms_projector_px, r->inliers, r->samples);
}

TEST(PlaneHomographyRoute, TypedErrors) {
  const auto projector = procam::testing::squarePixelProjector();
  const auto camera = procam::testing::camera640();
  const auto set = patternSet(projector);
  const sl::Decoded good = decodedMap(camera, projector, kWall, 0);

  // The plane given is behind the camera where it sees the projection.
  const geom::Plane behind = planeThrough(Vec3(0, -3, 0), Vec3(0, 1, 0));
  auto r = calib::solvePlaneHomographyRoute(set, {"cam", camera, good}, behind);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kDegenerate) << r.error().message;

  // A floor: no upright direction for the keystone's basis.
  const geom::Plane floor = planeThrough(Vec3(0, 0, -1), Vec3(0, 0, 1));
  r = calib::solvePlaneHomographyRoute(set, {"cam", camera, good}, floor);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kDegenerate) << r.error().message;

  // The camera sees a sliver of the projection (a fortieth of its width):
  // extrapolation refused.
  int left = camera.width, right = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x)
      if (good.flags.at<std::uint8_t>(y, x) == 0)
        left = std::min(left, x), right = std::max(right, x);
  ASSERT_GT(right - left, 80);
  sl::Decoded sliver = copyOf(good);
  const int band = (right - left) / 40, middle = (left + right) / 2;
  sliver.flags.colRange(0, middle).setTo(sl::kShadow);
  sliver.flags.colRange(middle + band, camera.width).setTo(sl::kShadow);
  r = calib::solvePlaneHomographyRoute(set, {"cam", camera, sliver}, kWall);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kDegenerate) << r.error().message;

  sl::Decoded nothing = copyOf(good);
  nothing.flags.setTo(sl::kShadow);
  r = calib::solvePlaneHomographyRoute(set, {"cam", camera, nothing}, kWall);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kTooFewPoints);

  geom::CameraModel other = camera;
  other.width = 320;
  r = calib::solvePlaneHomographyRoute(set, {"cam", other, good}, kWall);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);

  r = calib::solvePlaneHomographyRoute(set, {"cam", camera, good}, geom::Plane{Vec3::Zero(), 1});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
}

}  // namespace
