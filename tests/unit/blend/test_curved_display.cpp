// One display from three projectors on a cylinder wall for a sweet-spot viewer, solved
// with the TRUE projectors and wall of the cylinder3 scene (the geometry alone; the
// calibrated rig is judged end to end in tests/integration).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "blend/curved_display.hpp"
#include "render/viewer_view.hpp"
#include "sim/scene_library.hpp"
#include "unit/common/cylinder_wall.hpp"

namespace procam::blend {
namespace {

geom::MeshIntersector cylinderMesh() {
  return *geom::MeshIntersector::build(testing_support::cylinderWall());
}

struct Rig {
  geom::MeshIntersector wall = cylinderMesh();
  std::vector<SurfaceProjector> projectors;
  Vec3 eye;
};

// Filled in place: the projectors point at the rig's own wall.
void trueRig(Rig& rig) {
  auto scene = sim::resolveScene("cylinder3");
  EXPECT_TRUE(scene) << scene.error().message;
  const sim::SceneState s = scene->at(0);
  for (const auto& p : s.projectors) {
    rig.projectors.push_back(
        {&rig.wall, p.model.projectionMatrix(), cv::Size(p.model.width, p.model.height), nullptr});
  }
  rig.eye = s.viewer.pose.center();
}

std::optional<Vec3> surfacePoint(const Rig& rig, std::size_t m, const Vec2& u) {
  auto rays = render::pixelRays(rig.projectors[m].projector);
  auto hit = rig.wall.intersect(rays->through(u.x(), u.y()));
  return hit ? std::optional<Vec3>(hit->point) : std::nullopt;
}

// Inside the frame's outer pixel edges: the pixels there light the point.
// `margin` 0.5 from the outer edges: between the first and last pixel centres.
bool inFrame(const SurfaceProjector& p, const Vec2& u, double margin = 0) {
  return u.x() >= -0.5 + margin && u.y() >= -0.5 + margin && u.x() <= p.size.width - 0.5 - margin &&
         u.y() <= p.size.height - 0.5 - margin;
}

constexpr int kW = 4800, kH = 900;  // a panorama

TEST(CurvedDisplay, ProjectorsAgreeOnEveryContentPointTheyShareOnTheTrueCylinder) {
  Rig rig;
  trueRig(rig);
  ASSERT_EQ(rig.projectors.size(), 3u);
  auto blend = makeCurvedBlend(rig.projectors, {}, rig.eye, {kW, kH});
  ASSERT_TRUE(blend) << blend.error().message;
  const CurvedDisplay& d = blend->display;
  // Where two projectors light the same wall point they show the same content pixel:
  // only the lookup nodes' piecewise-linear interpolation differs, allowed a tenth of the
  // 0.3 px seam budget (0.03 projector px, 0.05 content px at 1.6 content px per
  // projector px).
  double worst = 0;
  int shared = 0;
  for (std::size_t m = 0; m < rig.projectors.size(); ++m) {
    const auto& g = d.lookup[m];
    for (int j = 0; j < g.rows; j += 2) {
      for (int i = 0; i < g.cols; i += 2) {
        const Vec2 c = g.at(i, j);
        if (c.x() < 0 || c.y() < 0 || c.x() > kW - 1 || c.y() > kH - 1) continue;
        const auto X = surfacePoint(rig, m, g.node(i, j));
        ASSERT_TRUE(X);
        for (std::size_t n = 0; n < rig.projectors.size(); ++n) {
          if (n == m) continue;
          const Vec2 u = (rig.projectors[n].projector * X->homogeneous()).hnormalized();
          if (!inFrame(rig.projectors[n], u, 0.5)) continue;
          const auto cn = render::gridSource(d.lookup[n], u);
          ASSERT_TRUE(cn);
          worst = std::max(worst, (*cn - c).norm());
          ++shared;
        }
      }
    }
  }
  std::printf("[ figures  ] %d shared nodes, largest disagreement %.4f content px\n", shared,
              worst);
  EXPECT_GT(shared, 1000);
  EXPECT_LE(worst, 0.05);
}

TEST(CurvedDisplay, ContentIsUprightInsideTheImagesAndAsLargeAsTheyAllow) {
  Rig rig;
  trueRig(rig);
  ASSERT_EQ(rig.projectors.size(), 3u);
  auto d = solveCurvedDisplay(rig.projectors, rig.eye, {kW, kH});
  ASSERT_TRUE(d) << d.error().message;
  // The content's rows are level: its x axis is horizontal in the world.
  const Mat3 M = d->viewer.leftCols<3>();
  const Vec3 f = M.row(2).transpose().normalized();
  auto onPlane = [&](double x, double y) {
    const Vec3 ray = M.inverse() * Vec3(x, y, 1);
    return Vec3(ray / ray.dot(f));
  };
  const Vec3 row = onPlane(kW - 1, 400) - onPlane(0, 400);
  EXPECT_LT(std::abs(row.z()) / row.norm(), 1e-9);
  EXPECT_NEAR(std::abs(row.normalized().dot(f.cross(Vec3::UnitZ()).normalized())), 1, 1e-9);
  // Every point of the content's border is shown; 2 % more and some is not.
  auto shown = [&](double x, double y) {
    const Vec3 dir = (M.inverse() * Vec3(x, y, 1)).normalized();
    auto hit = rig.wall.intersect({rig.eye, dir});
    if (!hit) return false;
    for (const auto& p : rig.projectors) {
      if (inFrame(p, (p.projector * hit->point.homogeneous()).hnormalized())) return true;
    }
    return false;
  };
  auto border = [&](double scale) {
    int missed = 0;
    const double cx = 0.5 * (kW - 1), cy = 0.5 * (kH - 1);
    for (int k = 0; k <= 200; ++k) {
      const double a = k / 200.0;
      for (const Vec2& p : {Vec2(a * kW - 0.5, -0.5), Vec2(a * kW - 0.5, kH - 0.5),
                            Vec2(-0.5, a * kH - 0.5), Vec2(kW - 0.5, a * kH - 0.5)}) {
        missed += !shown(cx + scale * (p.x() - cx), cy + scale * (p.y() - cy));
      }
    }
    return missed;
  };
  EXPECT_EQ(border(1.0), 0);
  EXPECT_GT(border(1.02), 0);
  // The three images, side by side on 240 deg of wall: the display is far wider than any
  // one projector's image (50 deg each, overlapping by ~15 %).
  const double wide_deg = 2 * std::atan(d->rect.half_width) * 180 / std::numbers::pi;
  std::printf("[ figures  ] display %.1f deg wide as the eye sees it, cell %.5f\n", wide_deg,
              d->cell);
  EXPECT_GT(wide_deg, 90);
}

TEST(CurvedDisplay, WeightsOfEveryWallPointSumToOne) {
  Rig rig;
  trueRig(rig);
  ASSERT_EQ(rig.projectors.size(), 3u);
  auto weights = curvedFeatherWeights(rig.projectors);
  ASSERT_TRUE(weights) << weights.error().message;
  double worst = 0, worst_inner = 0;
  int alone = 0, overlapped = 0;
  for (std::size_t m = 0; m < rig.projectors.size(); ++m) {
    for (int y = 3; y < 800; y += 17) {
      for (int x = 5; x < 1280; x += 17) {
        const auto X = surfacePoint(rig, m, Vec2(x, y));
        ASSERT_TRUE(X);
        double sum = 0;
        int lit = 0;
        bool inner = true;
        for (std::size_t n = 0; n < rig.projectors.size(); ++n) {
          const Vec2 u = (rig.projectors[n].projector * X->homogeneous()).hnormalized();
          if (!inFrame(rig.projectors[n], u)) continue;
          ++lit;
          inner = inner && inFrame(rig.projectors[n], u, 4);
          // Bilinear in the weight image.
          cv::Mat one;
          cv::getRectSubPix((*weights)[n], {1, 1}, cv::Point2f(u.x(), u.y()), one);
          sum += one.at<float>(0, 0);
        }
        (lit == 1 ? alone : overlapped)++;
        (inner ? worst_inner : worst) = std::max(inner ? worst_inner : worst, std::abs(sum - 1));
      }
    }
  }
  std::printf(
      "[ figures  ] %d points lit once, %d twice or more; weights sum to 1 within %.4f, %.4f "
      "within 4 px of a frame edge\n",
      alone, overlapped, worst_inner, worst);
  EXPECT_GT(overlapped, 200);
  // The weight nodes are 2 px apart: bilinear between them the sum is exact to the
  // weights' curvature over a node cell, except within a few pixels of where two frames'
  // edges cross (both distances near 0: eq. 4.3 is 0 / 0 there).
  EXPECT_LE(worst_inner, 0.005);
  EXPECT_LE(worst, 0.03);
  // A projector's seam edge fades to nothing, its outer edge does not.
  const cv::Mat& left = (*weights)[0];
  EXPECT_LT(left.at<float>(400, 1279), 0.01f);
  EXPECT_GT(left.at<float>(400, 0), 0.99f);
}

TEST(CurvedDisplay, BadInputIsRefused) {
  Rig rig;
  trueRig(rig);
  ASSERT_EQ(rig.projectors.size(), 3u);
  EXPECT_EQ(solveCurvedDisplay({}, rig.eye, {kW, kH}).error().code, ErrorCode::kInvalidInput);
  auto none = rig.projectors;
  none[1].surface = nullptr;
  EXPECT_EQ(solveCurvedDisplay(none, rig.eye, {kW, kH}).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(solveCurvedDisplay(rig.projectors, Vec3(NAN, 0, 0), {kW, kH}).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(solveCurvedDisplay(rig.projectors, rig.eye, {0, kH}).error().code,
            ErrorCode::kInvalidInput);
  // An eye near the wall has the images on the far side behind it.
  auto behind = solveCurvedDisplay(rig.projectors, Vec3(0, 2.5, 1.6), {kW, kH});
  ASSERT_FALSE(behind);
  EXPECT_EQ(behind.error().code, ErrorCode::kDegenerate) << behind.error().message;
  // Projectors turned away from the wall's mesh light nothing.
  auto away = rig.projectors;
  for (auto& p : away) p.projector.col(2) *= -1;
  auto missed = solveCurvedDisplay(away, rig.eye, {kW, kH});
  ASSERT_FALSE(missed);
  EXPECT_EQ(missed.error().code, ErrorCode::kDegenerate) << missed.error().message;
}

}  // namespace
}  // namespace procam::blend
