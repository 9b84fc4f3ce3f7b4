// End to end on the virtual rig with the mock output (CPU renderer):
//  - wall_oblique: the keystone pre-warp (homography path) makes the content appear on
//    the wall as an upright rectangle of the content's aspect, seen by the rig's camera
//    (keystone accuracy bounds: corner error <= 0.5 projector px at 1920x1080, aspect
//    within 0.1%);
//  - dome3, one projector, static viewer: the two-pass projective texture over a surface
//    mesh; the viewer perceives the content with <= 0.5 px geometric error.
// Features are Gaussian blobs whose centroids are measured in the rendered images.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "keystone/keystone_solver.hpp"
#include "mock/mock_output.hpp"
#include "render_test_rig.hpp"
#include "sim/scene_library.hpp"

namespace procam::output {
namespace {

// Black content with Gaussian blobs (sigma in content px) at `centres`, grey level `peak`.
cv::Mat blobContent(cv::Size size, const std::vector<Vec2>& centres, double sigma, double peak) {
  cv::Mat img(size, CV_8UC4, cv::Scalar(0, 0, 0, 255));
  const int r = static_cast<int>(std::ceil(4 * sigma));
  for (const Vec2& c : centres) {
    for (int y = int(c.y()) - r; y <= int(c.y()) + r + 1; ++y) {
      for (int x = int(c.x()) - r; x <= int(c.x()) + r + 1; ++x) {
        if (x < 0 || y < 0 || x >= size.width || y >= size.height) continue;
        const double d2 = (x - c.x()) * (x - c.x()) + (y - c.y()) * (y - c.y());
        const double v = peak * std::exp(-d2 / (2 * sigma * sigma));
        auto& p = img.at<cv::Vec4b>(y, x);
        const uint8_t b =
            static_cast<uint8_t>(std::min(255.0, std::max<double>(p[0], std::lround(v))));
        p = cv::Vec4b(b, b, b, 255);
      }
    }
  }
  return img;
}

// Intensity-weighted centroid in a window, background (window minimum) removed; nullopt
// when the window leaves the image.
std::optional<Vec2> centroid(const cv::Mat& gray, const Vec2& guess, int half) {
  const cv::Rect win(int(std::lround(guess.x())) - half, int(std::lround(guess.y())) - half,
                     2 * half + 1, 2 * half + 1);
  if ((win & cv::Rect(0, 0, gray.cols, gray.rows)) != win) return std::nullopt;
  cv::Mat w;
  gray(win).convertTo(w, CV_64F);
  double lo = 0, hi = 0;
  cv::minMaxLoc(w, &lo, &hi);
  if (hi - lo <= 0) return std::nullopt;
  double sx = 0, sy = 0, s = 0;
  for (int y = 0; y < w.rows; ++y) {
    for (int x = 0; x < w.cols; ++x) {
      // Keep the upper part of the blob: robust to the slow light fall-off under it.
      const double v = std::max(0.0, w.at<double>(y, x) - lo - 0.1 * (hi - lo));
      sx += v * (win.x + x);
      sy += v * (win.y + y);
      s += v;
    }
  }
  return Vec2(sx / s, sy / s);
}

TEST(RigEndToEnd, WallObliqueKeystoneShowsAnUprightRectangle) {
  auto scene = sim::resolveScene("wall_oblique");
  ASSERT_TRUE(scene) << scene.error().message;
  const sim::SceneState state = scene->at(0);
  const auto* proj = state.projector("proj");
  ASSERT_NE(proj, nullptr);
  const cv::Size fb(proj->spec.width, proj->spec.height), content(1920, 1080);
  keystone::KeystoneProblem problem;
  problem.K = proj->model.K;
  problem.width = fb.width;
  problem.height = fb.height;
  problem.R = proj->model.pose.R;  // the wall frame is the world frame (wall y = 3)
  problem.content_width = content.width;
  problem.content_height = content.height;
  auto solution = keystone::solveKeystone(problem);
  ASSERT_TRUE(solution) << solution.error().message;

  sim::Framebuffers board;
  auto out = MockOutput::create(*scene, "proj", &board);
  ASSERT_TRUE(out);
  render::RenderSetup setup;
  setup.output_size = fb;
  setup.content_size = content;
  setup.path = render::RenderPath::kHomography;
  setup.homography = solution->H;
  ASSERT_TRUE((*out)->configure(setup));
  // A 5 x 3 lattice of blobs spanning the content, corners included.
  std::vector<Vec2> blobs;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 5; ++i) blobs.emplace_back(60 + i * (1800.0 / 4), 60 + j * (960.0 / 2));
  const cv::Mat img = blobContent(content, blobs, 9.0, 200);
  ASSERT_TRUE((*out)->show({&img, nullptr, 1}));

  auto renderer = sim::Renderer::create(*scene, state, board);
  ASSERT_TRUE(renderer) << renderer.error().message;
  sim::RenderOptions opts;
  opts.seed = 5;
  auto cam_img = renderer->renderCamera("cam", opts);
  ASSERT_TRUE(cam_img) << cam_img.error().message;
  const auto* cam = state.camera("cam");
  const Mat34 P = proj->model.projectionMatrix();
  // Each blob: camera centroid -> ray -> wall point -> projector pixel.
  std::vector<Vec2> wall, seen_blobs;
  double worst_fb = 0;
  for (const Vec2& c : blobs) {
    const Vec2 fb_expected = (solution->H * c.homogeneous()).hnormalized();
    // Guess in the camera from the truth geometry: wall point lit by that framebuffer pixel.
    Vec3 o, d;
    test::pixelRay(P, fb_expected.x(), fb_expected.y(), o, d);
    const Vec3 W_guess = o + ((3.0 - o.y()) / d.y()) * d;
    const auto guess = cam->model.project(W_guess);
    ASSERT_TRUE(guess);
    const auto m = centroid(*cam_img, *guess, 12);
    if (!m) {
      std::printf("blob (%.0f, %.0f) outside the camera's view\n", c.x(), c.y());
      continue;
    }
    seen_blobs.push_back(c);
    const auto ray = sim::pixelRay(cam->model, m->x(), m->y());
    ASSERT_TRUE(ray);
    const Vec3 W = ray->origin + ((3.0 - ray->origin.y()) / ray->dir.y()) * ray->dir;
    wall.emplace_back(W.x(), W.z());
    const Vec2 fb_seen = (P * W.homogeneous()).hnormalized();
    worst_fb = std::max(worst_fb, (fb_seen - fb_expected).norm());
  }
  ASSERT_GE(seen_blobs.size(), 9u);
  blobs = seen_blobs;
  // Upright rectangle of the content's aspect: wall (X, Z) = origin + s (cx, -cy) with one
  // scale s for both axes; the fit residual in projector pixels is the corner error.
  Eigen::MatrixXd A(2 * blobs.size(), 4);
  Eigen::VectorXd b(2 * blobs.size());
  for (size_t k = 0; k < blobs.size(); ++k) {
    A.row(2 * k) << blobs[k].x(), 0, 1, 0;
    A.row(2 * k + 1) << 0, -blobs[k].y(), 0, 1;
    b(2 * k) = wall[k].x();
    b(2 * k + 1) = wall[k].y();
  }
  const Eigen::Vector4d fit = A.colPivHouseholderQr().solve(b);  // sx, sy, X0, Z0
  EXPECT_NEAR(fit(0) / fit(1), 1.0, 1e-3) << "aspect";
  const double s = 0.5 * (fit(0) + fit(1));
  double worst_rect = 0;
  for (size_t k = 0; k < blobs.size(); ++k) {
    const Vec3 ideal(fit(2) + s * blobs[k].x(), 3.0, fit(3) - s * blobs[k].y());
    const Vec3 seen(wall[k].x(), 3.0, wall[k].y());
    const Vec2 a = (P * ideal.homogeneous()).hnormalized(),
               c = (P * seen.homogeneous()).hnormalized();
    worst_rect = std::max(worst_rect, (a - c).norm());
  }
  EXPECT_LE(worst_rect, 0.5) << "deviation from an upright rectangle, projector px";
  EXPECT_LE(worst_fb, 0.5) << "blob position against the pre-warp, projector px";
  std::printf("wall_oblique: rectangle residual %.3f px, pre-warp error %.3f px, aspect %.5f\n",
              worst_rect, worst_fb, fit(0) / fit(1));
}

TEST(RigEndToEnd, Dome3TwoPassStaticViewerSeesTheContent) {
  auto scene = sim::resolveScene("dome3");
  ASSERT_TRUE(scene) << scene.error().message;
  const sim::SceneState state = scene->at(0);  // the viewer holds still at t = 0
  const auto* proj = state.projector("proj_a");
  ASSERT_NE(proj, nullptr);
  const cv::Size fb(proj->spec.width, proj->spec.height);
  const cv::Size view(state.viewer.width, state.viewer.height);
  // The display-surface model: the dome (centre 0, radius 2.5, axis +Z) as a fine mesh,
  // as calibration would deliver it (chord sag 2.5 m * (1 - cos(0.7 deg)) = 0.2 mm).
  render::SurfaceMesh dome;
  const int rings = 64, sectors = 256;
  for (int i = 0; i <= rings; ++i) {
    const double polar = (M_PI / 2) * i / rings;
    for (int k = 0; k <= sectors; ++k) {
      const double az = 2 * M_PI * k / sectors;
      dome.vertices.push_back(2.5 * Vec3(std::sin(polar) * std::cos(az),
                                         std::sin(polar) * std::sin(az), std::cos(polar)));
    }
  }
  for (int i = 0; i < rings; ++i) {
    for (int k = 0; k < sectors; ++k) {
      const int a = i * (sectors + 1) + k, b = a + sectors + 1;
      dome.triangles.push_back({a, b, a + 1});
      dome.triangles.push_back({a + 1, b, b + 1});
    }
  }
  sim::Framebuffers board;
  auto out = MockOutput::create(*scene, "proj_a", &board);
  ASSERT_TRUE(out);
  render::RenderSetup setup;
  setup.output_size = fb;
  setup.content_size = view;
  setup.path = render::RenderPath::kTwoPassMesh;
  setup.surface = dome;
  setup.projector = proj->model.projectionMatrix();
  setup.viewer = state.viewer.projectionMatrix();
  auto configured = (*out)->configure(setup);
  ASSERT_TRUE(configured) << configured.error().message;
  std::vector<Vec2> blobs;
  for (int j = 0; j < 7; ++j)
    for (int i = 0; i < 9; ++i)
      blobs.emplace_back(40 + i * (view.width - 80) / 8.0 + 0.3,
                         40 + j * (view.height - 80) / 6.0 + 0.7);
  const cv::Mat img = blobContent(view, blobs, 3.0, 220);
  ASSERT_TRUE((*out)->show({&img, nullptr, 1}));
  auto renderer = sim::Renderer::create(*scene, state, board);
  ASSERT_TRUE(renderer) << renderer.error().message;
  const cv::Mat radiance = renderer->renderViewer(4);
  cv::Mat gray;
  cv::cvtColor(radiance, gray, cv::COLOR_BGR2GRAY);
  // Blobs the projector lights fully: the content is dark outside its frame.
  auto map = render::projectiveTextureMap(dome, setup.projector, setup.viewer, fb);
  ASSERT_TRUE(map);
  cv::Mat reached(view, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < fb.height; ++y) {
    for (int x = 0; x < fb.width; ++x) {
      const cv::Vec2f v = map->xy.at<cv::Vec2f>(y, x);
      const int vx = int(std::lround(v[0])), vy = int(std::lround(v[1]));
      if (vx >= 0 && vy >= 0 && vx < view.width && vy < view.height)
        reached.at<uint8_t>(vy, vx) = 255;
    }
  }
  int measured = 0;
  double worst = 0;
  for (const Vec2& c : blobs) {
    const cv::Rect win(int(c.x()) - 12, int(c.y()) - 12, 25, 25);
    if (cv::countNonZero(reached(win)) < win.area()) continue;  // partly outside the projector
    const auto m = centroid(gray, c, 10);
    ASSERT_TRUE(m);
    worst = std::max(worst, (*m - c).norm());
    ++measured;
  }
  EXPECT_GE(measured, 10);
  EXPECT_LE(worst, 0.5);
  std::printf("dome3 proj_a: %d blobs, worst viewer error %.3f px\n", measured, worst);
}

}  // namespace
}  // namespace procam::output
