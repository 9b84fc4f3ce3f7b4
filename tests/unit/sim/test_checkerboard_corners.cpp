// A checkerboard shown by the wall_oblique projector, seen by its camera with noise
// off: the detected inner corners must land where analytic projection puts them
// (the simulator's geometric fidelity bound: within 0.05 px).
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "geometry/intersect.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"

namespace procam::sim {
namespace {

constexpr int kSquare = 100;          // framebuffer pixels per square
constexpr int kCols = 12, kRows = 8;  // squares
constexpr int kX0 = 360, kY0 = 140;   // first square's top-left pixel

// Squares cover whole pixels, so the edge between pixel k-1 and k lies at k - 0.5
// (pixel centres at integer coordinates).
cv::Mat checkerboard(int width, int height) {
  cv::Mat fb(height, width, CV_8UC1, cv::Scalar(255));
  for (int y = kY0; y < kY0 + kRows * kSquare; ++y) {
    for (int x = kX0; x < kX0 + kCols * kSquare; ++x) {
      const bool dark = (((x - kX0) / kSquare) + ((y - kY0) / kSquare)) % 2 == 0;
      fb.at<std::uint8_t>(y, x) = dark ? 0 : 255;
    }
  }
  return fb;
}

TEST(SimCheckerboard, CornersLandWhereAnalyticProjectionSays) {
  auto scene = resolveScene("wall_oblique");
  ASSERT_TRUE(scene) << scene.error().message;
  const SceneState state = scene->at(0.0);
  const ProjectorState& proj = state.projectors.at(0);
  const CameraState& cam = state.cameras.at(0);

  // Pattern, all-white and all-black frames, noise off. Like any structured-light
  // decoder, normalise by the white and black frames: the cos/d^2 falloff across the
  // oblique wall would otherwise bias the gradient-based corner refinement (by about
  // 0.01 px here), which is a property of the detector, not of the image geometry.
  RenderOptions options;
  options.noise = false;
  auto shot = [&](const cv::Mat& fb) -> cv::Mat {
    auto renderer = Renderer::create(*scene, state, {{"proj", fb}});
    if (!renderer) return {};
    auto image = renderer->renderCamera("cam", options);
    if (!image || image->type() != CV_8UC1) return {};
    cv::Mat f;
    image->convertTo(f, CV_32F);
    return f;
  };
  const cv::Size fb_size(proj.model.width, proj.model.height);
  const cv::Mat pattern = shot(checkerboard(fb_size.width, fb_size.height));
  const cv::Mat white = shot(cv::Mat(fb_size, CV_8UC1, cv::Scalar(255)));
  const cv::Mat black = shot(cv::Mat(fb_size, CV_8UC1, cv::Scalar(0)));
  ASSERT_FALSE(pattern.empty() || white.empty() || black.empty()) << "rendering failed";
  cv::Mat range = white - black;
  cv::max(range, 1.0, range);
  const cv::Mat normalized = (pattern - black) / range * 255.0;
  cv::Mat normalized8;
  normalized.convertTo(normalized8, CV_8U);

  // Truth: inner corner (i, j) of the framebuffer -> projector ray -> wall -> camera.
  const geom::Plane wall{Vec3(0, -1, 0), 3.0};  // y = 3
  std::vector<Vec2> truth;
  for (int j = 1; j < kRows; ++j) {
    for (int i = 1; i < kCols; ++i) {
      const Vec2 corner(kX0 + i * kSquare - 0.5, kY0 + j * kSquare - 0.5);
      auto ray = proj.model.backproject(corner);
      ASSERT_TRUE(ray);
      const auto hit = geom::intersectPlane(*ray, wall);
      ASSERT_TRUE(hit);
      const auto px = cam.model.project(hit->point);
      ASSERT_TRUE(px && cam.model.inImage(*px)) << "corner outside the camera image";
      truth.push_back(*px);
    }
  }

  std::vector<cv::Point2f> found;
  ASSERT_TRUE(cv::findChessboardCornersSB(normalized8, cv::Size(kCols - 1, kRows - 1), found,
                                          cv::CALIB_CB_ACCURACY))
      << "checkerboard not found in the rendered camera image";
  cv::cornerSubPix(normalized, found, cv::Size(8, 8), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
  ASSERT_EQ(found.size(), truth.size());

  double worst = 0, sum_sq = 0;
  for (const auto& f : found) {
    double nearest = 1e9;
    for (const auto& t : truth) nearest = std::min(nearest, std::hypot(f.x - t.x(), f.y - t.y()));
    worst = std::max(worst, nearest);
    sum_sq += nearest * nearest;
  }
  const double rms = std::sqrt(sum_sq / found.size());
  RecordProperty("corner_error_max_px", std::to_string(worst));
  RecordProperty("corner_error_rms_px", std::to_string(rms));
  std::printf("checkerboard corners: %zu, max error %.4f px, rms %.4f px\n", found.size(), worst,
              rms);
  EXPECT_LT(worst, 0.05);
}

}  // namespace
}  // namespace procam::sim
