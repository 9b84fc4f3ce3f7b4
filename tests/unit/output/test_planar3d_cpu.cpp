// The CPU back-end of the planar 3D path (A'4x4 P_T, [Raskar02] §4.2.2-4.2.3) against a
// double-precision ray-cast reference on random planar scenes, and against the GLES
// back-end on a cube.
//
// Comparisons skip a 1 px band around every place where the visible triangle changes
// (triangle edges, clipping boundaries, intersections) and the image border: two correct
// rasterizers may disagree by one pixel on edges (GL snaps vertices to a sub-pixel grid,
// the CPU keeps doubles), and both the GL-vs-CPU bounds and the coverage check
// are about the interiors.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "headless/headless_output.hpp"
#include "planar3d_scenes.hpp"
#include "render/cpu_renderer.hpp"
#include "render_test_images.hpp"

namespace procam::output {
namespace {

using render::ColoredMesh;

// Per projector pixel: the index of the visible triangle (-1: none) and its colour.
struct Reference {
  cv::Mat id;         // CV_32S
  cv::Mat color;      // CV_8UC4
  long overlaps = 0;  // pixels where two or more triangles were hit inside the depth range
};

// The pixel's ray meets the wall at Wp; the viewer sees there whatever its ray eye -> Wp
// meets first ([Raskar02] §4.2.1). A hit counts only inside A'P_T's clip volume, evaluated in
// double; colours are the world-space barycentric blend at the hit (perspective-correct).
Reference referenceRender(const test::Planar3dScene& s, const ColoredMesh& mesh, cv::Size size) {
  Reference r{cv::Mat(size, CV_32S, cv::Scalar(-1)), cv::Mat(size, CV_8UC4, cv::Scalar::all(0))};
  const Mat3 M = s.P.leftCols<3>();
  const Mat3 Minv = M.inverse();
  const Vec3 C = -Minv * s.P.col(3);
  const Vec3 n = s.S.u.cross(s.S.v);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const Vec3 d = Minv * Vec3(x, y, 1);
      const Vec3 wall = C + (n.dot(s.S.corner - C) / n.dot(d)) * d;
      const Vec3 D = wall - s.eye;
      double best = INFINITY;
      int hits = 0;
      for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        const auto& tri = mesh.triangles[t];
        const Vec3 &v0 = mesh.vertices[tri[0]], &v1 = mesh.vertices[tri[1]],
                   &v2 = mesh.vertices[tri[2]];
        Mat3 A;
        A << D, v0 - v1, v0 - v2;  // eye + l D = v0 + b (v1 - v0) + g (v2 - v0)
        if (std::abs(A.determinant()) < 1e-14) continue;
        const Vec3 lbg = A.colPivHouseholderQr().solve(v0 - s.eye);
        const double l = lbg[0], b = lbg[1], g = lbg[2];
        if (b < 0 || g < 0 || b + g > 1) continue;
        const Vec4 c = s.pixel3d * (s.eye + l * D).homogeneous();
        if (!(c.w() > 0) || c.z() < -c.w() || c.z() > c.w()) continue;
        ++hits;
        if (l >= best) continue;
        best = l;
        r.id.at<int>(y, x) = static_cast<int>(t);
        cv::Vec4d col = (1 - b - g) * cv::Vec4d(mesh.colors[tri[0]]) +
                        b * cv::Vec4d(mesh.colors[tri[1]]) + g * cv::Vec4d(mesh.colors[tri[2]]);
        r.color.at<cv::Vec4b>(y, x) =
            cv::Vec4b(cv::saturate_cast<uint8_t>(col[0]), cv::saturate_cast<uint8_t>(col[1]),
                      cv::saturate_cast<uint8_t>(col[2]), cv::saturate_cast<uint8_t>(col[3]));
      }
      if (hits >= 2) ++r.overlaps;
    }
  }
  return r;
}

// Pixels whose 3x3 neighbourhood shows one reference triangle (or none): a 1 px band
// around every change of the visible triangle, and the image border, are left out.
cv::Mat interiorMask(const cv::Mat& id) {
  cv::Mat mask(id.size(), CV_8U, cv::Scalar(0));
  for (int y = 1; y + 1 < id.rows; ++y) {
    for (int x = 1; x + 1 < id.cols; ++x) {
      const int c = id.at<int>(y, x);
      bool same = true;
      for (int dy = -1; dy <= 1 && same; ++dy)
        for (int dx = -1; dx <= 1 && same; ++dx) same = id.at<int>(y + dy, x + dx) == c;
      mask.at<uint8_t>(y, x) = same ? 255 : 0;
    }
  }
  return mask;
}

cv::Vec4b randomColor(std::mt19937& rng) {
  std::uniform_int_distribution<int> c(0, 255);
  return {uint8_t(c(rng)), uint8_t(c(rng)), uint8_t(c(rng)), 255};
}

cv::Mat renderCpu(const Mat4& pixel3d, cv::Size size, const ColoredMesh& mesh) {
  render::RenderSetup setup;
  setup.output_size = size;
  setup.path = render::RenderPath::kPlanar3d;
  setup.planar3d = pixel3d;
  render::CpuRenderer cpu;
  auto ok = cpu.configure(setup);
  EXPECT_TRUE(ok) << (ok ? "" : ok.error().message);
  auto drawn = cpu.render({nullptr, &mesh, 1});
  EXPECT_TRUE(drawn && *drawn) << (drawn ? "not drawn" : drawn.error().message);
  cv::Mat frame;
  EXPECT_TRUE(cpu.readFrame(frame));
  return frame;
}

TEST(Planar3dCpu, RandomScenesMatchTheDoubleReference) {
  const cv::Size size(320, 180);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u01(0, 1), ab(-0.2, 1.2), lam(-0.4, 6.0);
  // near 0.5, far 5 (viewer depth, metres): the random triangles cross both planes and
  // the viewer's own plane, so clipping is exercised on every scene.
  int scenes = 0;
  long compared = 0, overlaps = 0, mismatched = 0, clipped = 0;
  for (int trial = 0; trial < 40 && scenes < 8; ++trial) {
    const auto s = test::randomPlanar3dScene(rng, size.width, size.height, 0.5, 5.0);
    if (!s) continue;
    ++scenes;
    ColoredMesh mesh;
    auto vertex = [&](double a, double b, double l) {
      mesh.vertices.push_back(s->eye + l * (test::onS(s->S, a, b) - s->eye));
      mesh.colors.push_back(randomColor(rng));
      return static_cast<int>(mesh.vertices.size()) - 1;
    };
    // Planar quads parallel to the wall at random viewer distances (they overlap)...
    for (int q = 0; q < 4; ++q) {
      const double a0 = 0.8 * u01(rng), b0 = 0.8 * u01(rng), l = 0.3 + 2.5 * u01(rng);
      const double a1 = a0 + 0.2 + 0.4 * u01(rng), b1 = b0 + 0.2 + 0.4 * u01(rng);
      const int i0 = vertex(a0, b0, l), i1 = vertex(a1, b0, l), i2 = vertex(a1, b1, l),
                i3 = vertex(a0, b1, l);
      mesh.triangles.push_back({i0, i1, i2});
      mesh.triangles.push_back({i0, i2, i3});
    }
    // ... and free triangles spanning depths, some behind the viewer or past far.
    for (int t = 0; t < 8; ++t) {
      mesh.triangles.push_back({vertex(ab(rng), ab(rng), lam(rng)),
                                vertex(ab(rng), ab(rng), lam(rng)),
                                vertex(ab(rng), ab(rng), lam(rng))});
    }
    for (const Vec3& v : mesh.vertices) {
      const Vec4 c = s->pixel3d * v.homogeneous();
      if (!(c.w() > 0) || std::abs(c.z()) > c.w()) ++clipped;
    }
    const Reference ref = referenceRender(*s, mesh, size);
    const cv::Mat cpu = renderCpu(s->pixel3d, size, mesh);
    const cv::Mat mask = interiorMask(ref.id);
    overlaps += ref.overlaps;
    for (int y = 0; y < size.height; ++y) {
      for (int x = 0; x < size.width; ++x) {
        if (!mask.at<uint8_t>(y, x)) continue;
        ++compared;
        const cv::Vec4b a = cpu.at<cv::Vec4b>(y, x), b = ref.color.at<cv::Vec4b>(y, x);
        // Coverage and visibility: the same triangle, so the colour within the rounding
        // of a float32 interpolation (1 code value).
        bool ok = true;
        for (int k = 0; k < 4; ++k) ok = ok && std::abs(int(a[k]) - int(b[k])) <= 1;
        if (!ok) {
          if (mismatched < 5) {
            ADD_FAILURE() << "scene " << scenes << " pixel (" << x << ", " << y << "): cpu " << a
                          << " reference " << b << " triangle " << ref.id.at<int>(y, x);
          }
          ++mismatched;
        }
      }
    }
  }
  EXPECT_GE(scenes, 6);
  EXPECT_EQ(mismatched, 0);
  // The scenes must exercise what is checked: clipping, depth order and enough area.
  EXPECT_GT(clipped, 0);
  EXPECT_GT(overlaps, 1000);
  EXPECT_GT(compared, scenes * size.area() / 3);
  std::printf(
      "planar 3D cpu: %d scenes, %ld interior px compared, %ld with overlapping "
      "triangles, %ld clipped vertices, %ld mismatches\n",
      scenes, compared, overlaps, clipped, mismatched);
}

TEST(Planar3dCpu, NothingBehindTheProjectorIsDrawn) {
  // A plain pinhole projector (w = depth along its axis) and a triangle with a vertex
  // behind it: only the part in front may show, and it must not wrap around the image.
  const cv::Size size(64, 48);
  const Mat34 P =
      test::lookAtProjection(60, 31.5, 23.5, Vec3::Zero(), Vec3::UnitY(), Vec3::UnitZ());
  auto depth4 = render::pixelProjectionWithDepth(P, 0.1, 10.0);
  ASSERT_TRUE(depth4) << depth4.error().message;
  ColoredMesh mesh;
  // Right half-plane of the view at depth 2 joined to a point 1 m behind, to the left.
  mesh.vertices = {Vec3(0.05, 2, -2), Vec3(0.05, 2, 2), Vec3(-3, -1, 0)};
  mesh.colors.assign(3, cv::Vec4b(255, 255, 255, 255));
  mesh.triangles = {{0, 1, 2}};
  const cv::Mat f = renderCpu(*depth4, size, mesh);
  // Truth in double: a pixel is lit iff its ray meets the triangle in front of the near
  // plane. The part with y > 0.1 lies left of x = 0.05 (1.5 px right of the centre column)
  // only where the triangle's edges reach; the pixel ray's hit decides.
  const Mat3 Minv = P.leftCols<3>().inverse();
  long lit = 0, wrong = 0;
  for (int y = 1; y + 1 < size.height; ++y) {
    for (int x = 1; x + 1 < size.width; ++x) {
      auto inside = [&](double px, double py) {
        const Vec3 d = Minv * Vec3(px, py, 1);
        Mat3 A;
        A << d, mesh.vertices[0] - mesh.vertices[1], mesh.vertices[0] - mesh.vertices[2];
        const Vec3 lbg = A.colPivHouseholderQr().solve(mesh.vertices[0]);
        return lbg[0] * d.y() > 0.1 && lbg[1] >= 0 && lbg[2] >= 0 && lbg[1] + lbg[2] <= 1;
      };
      const bool truth = inside(x, y);
      // Skip the 1 px band where the neighbours disagree (the edges).
      bool edge = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) edge = edge || inside(x + dx, y + dy) != truth;
      if (edge) continue;
      const bool drawn = f.at<cv::Vec4b>(y, x)[3] != 0;
      lit += truth;
      wrong += drawn != truth;
    }
  }
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(lit, size.area() / 8);
}

TEST(Planar3dCpu, CubeMatchesTheGlBackEnd) {
  const cv::Size size(960, 540);
  auto out = HeadlessOutput::create(size);
  ASSERT_TRUE(out) << out.error().message;
  std::mt19937 rng(3);
  std::optional<test::Planar3dScene> s;
  while (!s) s = test::randomPlanar3dScene(rng, size.width, size.height, 0.1, 20.0);
  // A cube 0.4 m across half way between the viewer and the wall, turned so three faces
  // show, one random colour per corner of each face (smooth gradients), in front of a
  // quad behind the wall.
  ColoredMesh mesh;
  const Vec3 centre = s->eye + 0.6 * (test::onS(s->S, 0.5, 0.5) - s->eye);
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(0.6, Vec3::UnitZ()) * Eigen::AngleAxisd(0.4, Vec3::UnitX()))
          .toRotationMatrix();
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {-1, 1}) {
      const int base = static_cast<int>(mesh.vertices.size());
      for (auto [p, q] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
        Vec3 c;
        c[axis] = sign;
        c[(axis + 1) % 3] = p;
        c[(axis + 2) % 3] = q;
        mesh.vertices.push_back(centre + R * (0.2 * c));
        mesh.colors.push_back(randomColor(rng));
      }
      mesh.triangles.push_back({base, base + 1, base + 2});
      mesh.triangles.push_back({base, base + 2, base + 3});
    }
  }
  const int base = static_cast<int>(mesh.vertices.size());
  for (auto [a, b] : {std::pair{0.1, 0.1}, {0.9, 0.1}, {0.9, 0.9}, {0.1, 0.9}}) {
    mesh.vertices.push_back(s->eye + 1.4 * (test::onS(s->S, a, b) - s->eye));
    mesh.colors.push_back(randomColor(rng));
  }
  mesh.triangles.push_back({base, base + 1, base + 2});
  mesh.triangles.push_back({base, base + 2, base + 3});

  render::RenderSetup setup;
  setup.output_size = size;
  setup.path = render::RenderPath::kPlanar3d;
  setup.planar3d = s->pixel3d;
  auto configured = (*out)->configure(setup);
  ASSERT_TRUE(configured) << configured.error().message;
  auto shown = (*out)->show({nullptr, &mesh, 1});
  ASSERT_TRUE(shown && *shown) << (shown ? "not shown" : shown.error().message);
  const cv::Mat gl = (*out)->lastFrame().clone();
  const cv::Mat cpu = renderCpu(s->pixel3d, size, mesh);
  const Reference ref = referenceRender(*s, mesh, size);
  const cv::Mat mask = interiorMask(ref.id);
  const test::Difference d = test::compare(gl, cpu, mask);
  ::testing::Test::RecordProperty("cube_mean_abs", std::to_string(d.mean_abs));
  ::testing::Test::RecordProperty("cube_psnr", std::to_string(d.psnr));
  EXPECT_GT(d.pixels, size.area() / 4);
  EXPECT_LE(d.mean_abs, 1.0);  // 1/255 of full scale
  EXPECT_GE(d.psnr, 45.0);
  // Both show the cube where the reference does: its faces hold most of the compared area
  // that is not background quad.
  long cube_px = 0;
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      cube_px += mask.at<uint8_t>(y, x) && ref.id.at<int>(y, x) >= 0 && ref.id.at<int>(y, x) < 12;
  EXPECT_GT(cube_px, size.area() / 50);
  std::printf(
      "planar 3D cube GL vs CPU: mean abs %.4f, max %.0f, PSNR %.2f dB over %ld px "
      "(%ld on the cube)\n",
      d.mean_abs, d.max_abs, d.psnr, d.pixels, cube_px);
}

}  // namespace
}  // namespace procam::output
