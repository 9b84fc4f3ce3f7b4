#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "keystone/wall_normal.hpp"

namespace procam::keystone {
namespace {

struct Rig {
  geom::Intrinsics proj{1600, 1600, 959.5, 539.5, 0};
  geom::Intrinsics cam{1200, 1200, 639.5, 479.5, 0};
  geom::Pose cam_from_proj;
  Vec3 normal;  // projector frame, into the wall
  double distance = 2.5;

  Rig(double yaw_deg, double pitch_deg) {
    cam_from_proj.R = Eigen::AngleAxisd(-0.1, Vec3::UnitY()).toRotationMatrix();
    cam_from_proj.t = Vec3(-0.12, 0.02, 0.01);  // camera 12 cm to the right
    normal = (Eigen::AngleAxisd(yaw_deg * M_PI / 180, Vec3::UnitY()) *
              Eigen::AngleAxisd(pitch_deg * M_PI / 180, Vec3::UnitX()) * Vec3::UnitZ());
  }
  // Camera pixel of projector pixel x on the wall.
  Vec2 observe(const Vec2& x) const {
    const Vec3 ray = proj.matrix().inverse() * x.homogeneous();
    const Vec3 X = ray * distance / normal.dot(ray);
    return (cam.matrix() * cam_from_proj.toDevice(X)).hnormalized();
  }
};

TEST(WallNormal, ExactFromNoiseFreeCorrespondences) {
  for (auto [yaw, pitch] : {std::pair{0.0, 0.0}, {30.0, -20.0}, {-25.0, 40.0}}) {
    Rig rig(yaw, pitch);
    std::vector<Vec2> xp, xc;
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 4; ++j) {
        xp.emplace_back(200 + 380 * i, 150 + 260 * j);
        xc.push_back(rig.observe(xp.back()));
      }
    auto w = wallFromCorrespondences(rig.proj, rig.cam, rig.cam_from_proj, xp, xc);
    ASSERT_TRUE(w) << w.error().message;
    EXPECT_NEAR((w->normal - rig.normal).norm(), 0, 1e-9);
    EXPECT_NEAR(w->distance, rig.distance, 1e-9);
    EXPECT_LT(w->rms, 1e-6);
  }
}

TEST(WallNormal, NoisyCameraResidualMatchesTheNoise) {
  // With Gaussian pixel noise sigma per axis, the ML fit's 2D residual RMS is
  // sigma * sqrt((2n - 3) / n) (3 parameters fitted): within 15% for n = 300.
  Rig rig(20, 10);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.5);
  std::uniform_real_distribution<double> ux(0, 1919), uy(0, 1079);
  std::vector<Vec2> xp, xc;
  for (int i = 0; i < 300; ++i) {
    xp.emplace_back(ux(rng), uy(rng));
    xc.push_back(rig.observe(xp.back()) + Vec2(noise(rng), noise(rng)));
  }
  auto w = wallFromCorrespondences(rig.proj, rig.cam, rig.cam_from_proj, xp, xc);
  ASSERT_TRUE(w);
  EXPECT_NEAR(w->rms, 0.5 * std::sqrt((600.0 - 3) / 300), 0.15 * 0.5 * std::sqrt(2.0));
  EXPECT_LT(std::acos(std::min(1.0, w->normal.dot(rig.normal))), 0.01);
}

TEST(WallNormal, TypedErrors) {
  Rig rig(0, 0);
  std::vector<Vec2> xp = {{100, 100}, {500, 500}, {900, 900}, {1300, 1300}}, xc;
  for (const Vec2& x : xp) xc.push_back(rig.observe(x));
  EXPECT_EQ(wallFromCorrespondences(rig.proj, rig.cam, rig.cam_from_proj, xp, xc).error().code,
            ErrorCode::kIllConditioned);  // collinear
  EXPECT_EQ(wallFromCorrespondences(rig.proj, rig.cam, rig.cam_from_proj, std::span(xp).first(2),
                                    std::span(xc).first(2))
                .error()
                .code,
            ErrorCode::kTooFewPoints);
  geom::Pose no_baseline = rig.cam_from_proj;
  no_baseline.t.setZero();
  xp = {{100, 100}, {1800, 120}, {900, 1000}};
  xc.clear();
  for (const Vec2& x : xp) xc.push_back(rig.observe(x));
  EXPECT_EQ(wallFromCorrespondences(rig.proj, rig.cam, no_baseline, xp, xc).error().code,
            ErrorCode::kDegenerate);
  xc[1].x() = NAN;
  EXPECT_EQ(wallFromCorrespondences(rig.proj, rig.cam, rig.cam_from_proj, xp, xc).error().code,
            ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::keystone
