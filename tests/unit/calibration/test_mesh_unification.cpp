// Surface mesh unification ([Raskar02] eq. 4.4) on two projectors' meshes of one wall,
// each triangulated with its own depth noise: in the overlap the unified meshes agree,
// every vertex stays on the ray of the pixel that lit it, and outside the overlap nothing
// moves.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "geometry/camera_model.hpp"
#include "surface/mesh_unification.hpp"

namespace procam::surface {
namespace {

// A projector's mesh of the wall y = 3: nodes every 16 px, each at the true wall point of
// its pixel moved along the ray by Gaussian noise of `sigma` metres.
UnifyProjector noisyWallMesh(const Vec3& eye, const Vec3& target, double sigma, unsigned seed) {
  geom::CameraModel p;
  p.K.fx = p.K.fy = 1000;
  p.K.cx = 319.5;
  p.K.cy = 199.5;
  p.width = 640;
  p.height = 400;
  p.pose = geom::Pose::lookAt(eye, target, Vec3::UnitZ());
  UnifyProjector out;
  out.P = p.projectionMatrix();
  out.size = cv::Size(640, 400);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, sigma);
  constexpr int kStep = 16, kCols = 640 / kStep + 1, kRows = 400 / kStep + 1;
  for (int j = 0; j < kRows; ++j) {
    for (int i = 0; i < kCols; ++i) {
      const Vec2 u(std::min(i * kStep, 639), std::min(j * kStep, 399));
      const Vec3 dir = p.pose.R.transpose() * p.K.matrix().inverse() * u.homogeneous();
      const Vec3 c = p.pose.center();
      const double t = (3.0 - c.y()) / dir.y();
      out.mesh.vertices.push_back(c + dir * t * (1 + noise(rng) / (dir.norm() * t)));
      out.mesh.projector.push_back(u);
    }
  }
  for (int j = 0; j + 1 < kRows; ++j) {
    for (int i = 0; i + 1 < kCols; ++i) {
      const int k = j * kCols + i;
      out.mesh.faces.push_back({k, k + 1, k + kCols});
      out.mesh.faces.push_back({k + 1, k + kCols + 1, k + kCols});
    }
  }
  return out;
}

TEST(MeshUnification, OverlappingMeshesAgreeAndStayOnTheirRays) {
  std::vector<UnifyProjector> rig = {
      noisyWallMesh(Vec3(-0.5, 0, 1.2), Vec3(-0.55, 3, 1.2), 0.002, 1),
      noisyWallMesh(Vec3(0.5, 0, 1.2), Vec3(0.55, 3, 1.2), 0.002, 2)};
  const std::vector<UnifyProjector> before = rig;
  auto report = unifyMeshes(rig);
  ASSERT_TRUE(report) << report.error().message;
  std::printf(
      "[ figures  ] %d of %d vertices shared; meshes %.2f mm apart RMS (max %.2f) "
      "before, %.2f mm (max %.2f) after\n",
      report->shared, report->vertices, 1000 * report->gap_rms_m, 1000 * report->gap_max_m,
      1000 * report->gap_after_rms_m, 1000 * report->gap_after_max_m);
  EXPECT_GT(report->shared, 100);
  EXPECT_LT(report->shared, report->vertices);
  // Two independent 2 mm depth errors differ by 2.8 mm RMS; eq. 4.4's weighted mean
  // leaves the meshes apart only by the noise the other mesh's triangles interpolate
  // between its own vertices.
  EXPECT_NEAR(report->gap_rms_m, 0.002 * std::sqrt(2.0), 0.0006);
  EXPECT_LT(report->gap_after_rms_m, 0.5 * report->gap_rms_m);
  for (std::size_t m = 0; m < 2; ++m) {
    int moved = 0;
    for (std::size_t k = 0; k < rig[m].mesh.vertices.size(); ++k) {
      const Vec3& X = rig[m].mesh.vertices[k];
      const Vec3 x = rig[m].P * X.homogeneous();
      // On the ray of the pixel that lit it.
      EXPECT_LT((x.hnormalized() - rig[m].mesh.projector[k]).norm(), 1e-6);
      if ((X - before[m].mesh.vertices[k]).norm() > 1e-12) ++moved;
      // Far outside the other's image (its own outer half): untouched.
      const double u = rig[m].mesh.projector[k].x();
      if ((m == 0 && u < 100) || (m == 1 && u > 540)) {
        EXPECT_EQ(X, before[m].mesh.vertices[k]) << m << " " << k;
      }
    }
    EXPECT_GT(moved, 50);
  }
}

TEST(MeshUnification, BadInputIsRefused) {
  std::vector<UnifyProjector> rig = {noisyWallMesh(Vec3(-0.5, 0, 1.2), Vec3(0, 3, 1.2), 0, 1)};
  UnifyOptions bad;
  bad.max_gap_m = 0;
  EXPECT_EQ(unifyMeshes(rig, bad).error().code, ErrorCode::kInvalidInput);
  auto broken = rig;
  broken[0].size = cv::Size(1, 1);
  EXPECT_EQ(unifyMeshes(broken).error().code, ErrorCode::kInvalidInput);
  broken = rig;
  broken[0].P.setZero();
  EXPECT_EQ(unifyMeshes(broken).error().code, ErrorCode::kInvalidInput);
  broken = rig;
  broken[0].mesh.projector.pop_back();
  EXPECT_EQ(unifyMeshes(broken).error().code, ErrorCode::kInvalidInput);
  broken = rig;
  broken[0].mesh.projector[3] = Vec2(std::nan(""), 0);
  EXPECT_EQ(unifyMeshes(broken).error().code, ErrorCode::kInvalidInput);
  broken = rig;
  broken[0].mesh.projector[3] = Vec2(1e12, 0);
  EXPECT_EQ(unifyMeshes(broken).error().code, ErrorCode::kInvalidInput);
  broken = rig;
  broken[0].mesh.faces.push_back({0, 1, 1 << 20});
  EXPECT_EQ(unifyMeshes(broken).error().code, ErrorCode::kInvalidInput);
  // One mesh alone: nothing to unify, nothing moves.
  auto alone = unifyMeshes(rig);
  ASSERT_TRUE(alone);
  EXPECT_EQ(alone->shared, 0);
}

}  // namespace
}  // namespace procam::surface
