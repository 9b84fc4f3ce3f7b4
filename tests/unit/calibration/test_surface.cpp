#include <gtest/gtest.h>

#include "surface/projector_samples.hpp"
#include "surface/stereo_points.hpp"
#include "surface/surface_model.hpp"
#include "synthetic_rig.hpp"

using namespace procam;
using namespace procam::surface;
using procam::testing::litPoint;
using procam::testing::planeThrough;

namespace {

// A decoded map as the Gray decoder returns it for a camera that sees projector
// point H(x, y): cell centres of 1-pixel cells (quantised to integers).
sl::Decoded quantisedMap(const Mat3& H, cv::Size size) {
  sl::Decoded d;
  d.u.create(size, CV_32F);
  d.v.create(size, CV_32F);
  d.confidence = cv::Mat(size, CV_32F, cv::Scalar(1));
  d.flags = cv::Mat(size, CV_8U, cv::Scalar(0));
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      const Vec3 p = H * Vec3(x, y, 1);
      d.u.at<float>(y, x) = static_cast<float>(std::round(p.x() / p.z()));
      d.v.at<float>(y, x) = static_cast<float>(std::round(p.y() / p.z()));
    }
  d.decoded = size.area();
  return d;
}

geom::CameraModel secondCamera() {
  auto c = procam::testing::camera640();
  c.pose = geom::Pose::lookAt(Vec3(0.55, -1.85, 0.5), Vec3(0.0, 0.0, 0.45), Vec3::UnitZ());
  return c;
}

// Exact samples of each camera for the projector nodes lit on `surface`.
ProjectorSamples exactSamples(const geom::CameraModel& projector, const geom::CameraModel& cam,
                              const std::function<std::optional<Vec3>(const Vec2&)>& surface,
                              int step) {
  ProjectorSamples s;
  s.step = step;
  s.nodes_x = (projector.width - 1) / step + 1;
  s.nodes_y = (projector.height - 1) / step + 1;
  s.index.assign(static_cast<std::size_t>(s.nodes_x) * s.nodes_y, -1);
  for (int j = 0; j < s.nodes_y; ++j)
    for (int i = 0; i < s.nodes_x; ++i) {
      const Vec2 q(i * step, j * step);
      auto x = surface(q);
      if (!x) continue;
      auto c = cam.project(*x);
      if (!c || !cam.inImage(*c)) continue;
      s.index[static_cast<std::size_t>(j) * s.nodes_x + i] = static_cast<int>(s.camera.size());
      s.camera.push_back(*c);
      s.projector.push_back(q);
    }
  return s;
}

}  // namespace

TEST(ProjectorSamples, InvertsAQuantisedMapToSubPixel) {
  // Camera pixel -> projector: about 1.6 projector px per camera px, mild perspective.
  Mat3 H;
  H << 1.6, 0.1, 20, -0.05, 1.5, 30, 1e-4, 5e-5, 1;
  const auto d = quantisedMap(H, cv::Size(320, 240));
  auto s = sampleProjectorGrid(d, 560, 420, {.step = 8, .radius = 3.0});
  ASSERT_TRUE(s);
  EXPECT_EQ(s->nodes_x, 70);
  EXPECT_EQ(s->nodes_y, 53);
  ASSERT_GT(s->camera.size(), 1500u);
  const Mat3 Hinv = H.inverse();
  double sum = 0, worst = 0;
  for (std::size_t k = 0; k < s->camera.size(); ++k) {
    const Vec3 c = Hinv * Vec3(s->projector[k].x(), s->projector[k].y(), 1);
    const double e = (s->camera[k] - c.hnormalized()).norm();
    sum += e * e;
    worst = std::max(worst, e);
  }
  // Integer quantisation is +-0.5 projector px = +-0.3 camera px; the local fit over
  // ~10 camera pixels averages it to a small fraction of that.
  EXPECT_LT(std::sqrt(sum / s->camera.size()), 0.1);
  EXPECT_LT(worst, 0.3);
  // Nodes outside what the camera sees have no sample.
  EXPECT_EQ(s->at(0, 0), -1);
}

TEST(ProjectorSamples, RejectsBadInput) {
  sl::Decoded empty;
  EXPECT_EQ(sampleProjectorGrid(empty, 100, 100, {}).error().code, ErrorCode::kInvalidInput);
  Mat3 H = Mat3::Identity();
  EXPECT_EQ(
      sampleProjectorGrid(quantisedMap(H, cv::Size(10, 10)), 100, 100, {.step = 0}).error().code,
      ErrorCode::kInvalidInput);
}

TEST(Surface, CornerIsTriangulatedMeshedWithHolesAndExported) {
  const auto projector = procam::testing::projector1024();
  const auto a = procam::testing::camera640();
  const auto b = secondCamera();
  const geom::Plane left = planeThrough(Vec3(0, 0.5, 0), Vec3(1, -1, 0));
  const geom::Plane right = planeThrough(Vec3(0, 0.5, 0), Vec3(-1, -1, 0));
  // A concave corner (the walls of a room), with a 40x40 px patch the decoder lost.
  auto corner = [&](const Vec2& q) -> std::optional<Vec3> {
    if (q.x() >= 400 && q.x() < 440 && q.y() >= 300 && q.y() < 340) return std::nullopt;
    auto l = litPoint(projector, q, left), r = litPoint(projector, q, right);
    if (!l || !r) return std::nullopt;
    return l->y() < r->y() ? l : r;
  };
  const int step = 8;
  auto pts = triangulateStereo(a, exactSamples(projector, a, corner, step), b,
                               exactSamples(projector, b, corner, step));
  ASSERT_TRUE(pts) << pts.error().message;
  ASSERT_GT(pts->world.size(), 3000u);
  for (std::size_t k = 0; k < pts->world.size(); ++k) {
    auto truth = corner(pts->projector[k]);
    ASSERT_TRUE(truth);
    EXPECT_LT((pts->world[k] - *truth).norm(), 1e-6);
  }
  auto model = buildSurface(*pts);
  ASSERT_TRUE(model) << model.error().message;
  EXPECT_FALSE(model->planar);
  EXPECT_LT(model->inlier_fraction, 0.9);
  const SurfaceMesh& mesh = model->mesh;
  ASSERT_GT(mesh.faces.size(), 100u);
  // Simplified: far fewer vertices than samples (flat walls become large quads).
  EXPECT_LT(mesh.vertices.size(), pts->world.size() / 4);
  // Every vertex lies on a wall and no triangle covers the lost patch.
  for (std::size_t k = 0; k < mesh.vertices.size(); ++k)
    EXPECT_LT(std::min(std::abs(left.signedDistance(mesh.vertices[k])),
                       std::abs(right.signedDistance(mesh.vertices[k]))),
              1e-6);
  for (const auto& f : mesh.faces) {
    const Vec2 c = (mesh.projector[f.x()] + mesh.projector[f.y()] + mesh.projector[f.z()]) / 3;
    EXPECT_FALSE(c.x() > 400 && c.x() < 440 - step && c.y() > 300 && c.y() < 340 - step);
  }
  const std::string ply = toPly(mesh);
  EXPECT_EQ(ply.rfind("ply\nformat ascii 1.0\n", 0), 0u);
  EXPECT_NE(ply.find("element vertex " + std::to_string(mesh.vertices.size()) + "\n"),
            std::string::npos);
  EXPECT_NE(ply.find("element face " + std::to_string(mesh.faces.size()) + "\n"),
            std::string::npos);
}

TEST(Surface, PlanarWallIsAPlane) {
  const auto projector = procam::testing::projector1024();
  const auto a = procam::testing::camera640();
  const auto b = secondCamera();
  const geom::Plane wall = planeThrough(Vec3(0, 0.5, 0), Vec3(0.3, -1, 0.1));
  auto lit = [&](const Vec2& q) { return litPoint(projector, q, wall); };
  auto pts = triangulateStereo(a, exactSamples(projector, a, lit, 16), b,
                               exactSamples(projector, b, lit, 16));
  ASSERT_TRUE(pts);
  auto model = buildSurface(*pts);
  ASSERT_TRUE(model);
  EXPECT_TRUE(model->planar);
  EXPECT_TRUE(model->mesh.faces.empty());
  EXPECT_LT(std::abs(std::abs(model->plane.n.dot(wall.n)) - 1), 1e-9);
  EXPECT_LT(model->plane_rms, 1e-6);
}
