// The planar 3D path ([Raskar02] §4.2.2-4.2.3, eq. 4.10): A'4x4 P_T evaluated by GL in float32
// against double-precision geometry, for random oblique projectors and tracked viewers.
// Bounds: no clipped geometry, visibility order preserved, pixel error <= 0.05 px.
#include <gtest/gtest.h>

#include <random>

#include "egl/egl_context.hpp"
#include "headless/headless_output.hpp"
#include "planar3d_scenes.hpp"
#include "render/gl_conventions.hpp"

namespace procam::output {
namespace {

constexpr int kW = 1920, kH = 1080;

using Scene = test::Planar3dScene;
using test::onS;

std::optional<Scene> randomScene(std::mt19937& rng) {
  return test::randomPlanar3dScene(rng, kW, kH);
}

// GL's float32 vertex stage, captured with transform feedback: clip = uClip * (X, 1),
// the computation of the renderer's colour program.
std::vector<Vec4> glClip(const Mat4& clip, const std::vector<Vec3>& points) {
  const char* vs = R"(#version 300 es
layout(location = 0) in vec3 aWorld;
uniform mat4 uClip;
out vec4 vClip;
void main() { vClip = uClip * vec4(aWorld, 1.0); gl_Position = vClip; })";
  const char* fs = R"(#version 300 es
precision highp float;
out vec4 o;
void main() { o = vec4(1.0); })";
  auto shader = [](GLenum type, const char* src) {
    GLuint s = glCreateShader(type);
    glShaderSource(s, 1, &src, nullptr);
    glCompileShader(s);
    return s;
  };
  GLuint prog = glCreateProgram();
  GLuint v = shader(GL_VERTEX_SHADER, vs), f = shader(GL_FRAGMENT_SHADER, fs);
  glAttachShader(prog, v);
  glAttachShader(prog, f);
  const char* names[] = {"vClip"};
  glTransformFeedbackVaryings(prog, 1, names, GL_INTERLEAVED_ATTRIBS);
  glLinkProgram(prog);
  GLint linked = 0;
  glGetProgramiv(prog, GL_LINK_STATUS, &linked);
  EXPECT_TRUE(linked);
  glUseProgram(prog);
  float m[16];
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) m[c * 4 + r] = static_cast<float>(clip(r, c));
  glUniformMatrix4fv(glGetUniformLocation(prog, "uClip"), 1, GL_FALSE, m);
  std::vector<float> in;
  for (const Vec3& p : points) in.insert(in.end(), {float(p.x()), float(p.y()), float(p.z())});
  // A surfaceless context has no default framebuffer: draw calls need a complete FBO
  // even with rasterisation discarded.
  GLuint fbo = 0, rb = 0;
  glGenFramebuffers(1, &fbo);
  glGenRenderbuffers(1, &rb);
  glBindRenderbuffer(GL_RENDERBUFFER, rb);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, 1, 1);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);
  GLuint vao = 0, bufs[2] = {0, 0};
  glGenVertexArrays(1, &vao);
  glGenBuffers(2, bufs);
  glBindVertexArray(vao);
  glBindBuffer(GL_ARRAY_BUFFER, bufs[0]);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(in.size() * 4), in.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  const GLsizeiptr out_bytes = static_cast<GLsizeiptr>(points.size() * 16);
  glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, bufs[1]);
  glBufferData(GL_TRANSFORM_FEEDBACK_BUFFER, out_bytes, nullptr, GL_STATIC_READ);
  glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, bufs[1]);
  glEnable(GL_RASTERIZER_DISCARD);
  glBeginTransformFeedback(GL_POINTS);
  glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(points.size()));
  glEndTransformFeedback();
  glDisable(GL_RASTERIZER_DISCARD);
  const auto* out = static_cast<const float*>(
      glMapBufferRange(GL_TRANSFORM_FEEDBACK_BUFFER, 0, out_bytes, GL_MAP_READ_BIT));
  std::vector<Vec4> clips;
  for (size_t i = 0; out && i < points.size(); ++i) {
    clips.emplace_back(out[4 * i], out[4 * i + 1], out[4 * i + 2], out[4 * i + 3]);
  }
  glUnmapBuffer(GL_TRANSFORM_FEEDBACK_BUFFER);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  glDeleteBuffers(2, bufs);
  glDeleteFramebuffers(1, &fbo);
  glDeleteRenderbuffers(1, &rb);
  glDeleteVertexArrays(1, &vao);
  glDeleteShader(v);
  glDeleteShader(f);
  glDeleteProgram(prog);
  return clips;
}

TEST(Planar3d, Float32PathAgainstDoubleGeometry) {
  // The GPU's own transform of the vertices, in a context of this test (outputs release
  // theirs after every call).
  auto context = egl::EglContext::surfaceless();
  ASSERT_TRUE(context) << context.error().message;
  ASSERT_TRUE((*context)->makeCurrent());
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u01(0, 1), depth(0.3, 3.0);
  const Mat4 to_clip =
      render::glConventions(kW, kH, render::GlOrigin::kRow0AtGlBottom).clip_from_pixel;
  int scenes = 0;
  double worst_px = 0;
  for (int trial = 0; trial < 40 && scenes < 25; ++trial) {
    const auto scene = randomScene(rng);
    if (!scene) continue;
    ++scenes;
    // Pairs of virtual points on one viewer ray through S, in front of and behind the wall
    // (lambda scales eye -> wall point), the second at least 1% farther.
    std::vector<Vec3> points;
    std::vector<Vec2> truth;
    for (int k = 0; k < 200; ++k) {
      const Vec3 wall = onS(scene->S, 0.02 + 0.96 * u01(rng), 0.02 + 0.96 * u01(rng));
      const double l1 = depth(rng), l2 = l1 * (1.01 + 0.5 * u01(rng));
      points.push_back(scene->eye + l1 * (wall - scene->eye));
      points.push_back(scene->eye + l2 * (wall - scene->eye));
      // Both points appear where the viewer's ray meets the wall: P * wall.
      const Vec2 px = (scene->P * wall.homogeneous()).hnormalized();
      truth.push_back(px);
      truth.push_back(px);
    }
    const std::vector<Vec4> clip = glClip(to_clip * scene->pixel3d, points);
    ASSERT_EQ(clip.size(), points.size());
    for (size_t i = 0; i < clip.size(); ++i) {
      const Vec4& c = clip[i];
      // No clipping: inside the canonical view volume, depth included (eq. 4.9).
      ASSERT_GT(c.w(), 0) << "scene " << scenes << " point " << i;
      ASSERT_LE(std::abs(c.z()), c.w()) << "depth clipped, scene " << scenes << " point " << i;
      // Points of S's interior fall inside the projector image only where the projector
      // lights the wall; x, y clipping there is the image border, not a depth problem.
      const Vec2 ndc(c.x() / c.w(), c.y() / c.w());
      const Vec2 px(((ndc.x() + 1) * kW - 1) / 2, ((ndc.y() + 1) * kH - 1) / 2);
      const double err = (px - truth[i]).norm();
      worst_px = std::max(worst_px, err);
      ASSERT_LE(err, 0.05) << "scene " << scenes << " point " << i;
      if (i % 2 == 1) {
        // Visibility: the nearer point of the pair has the smaller depth value.
        ASSERT_LT(clip[i - 1].z() / clip[i - 1].w(), c.z() / c.w()) << "order, point " << i;
      }
    }
  }
  EXPECT_GE(scenes, 20);
  std::printf("planar 3D: %d scenes, worst pixel error %.5f px\n", scenes, worst_px);
}

TEST(Planar3d, RenderedNearerSurfaceHidesFartherAndLandsWhereExpected) {
  std::mt19937 rng(11);
  std::optional<Scene> scene;
  while (!scene) scene = randomScene(rng);
  auto out = HeadlessOutput::create({kW, kH});
  ASSERT_TRUE(out);
  render::RenderSetup s;
  s.output_size = {kW, kH};
  s.path = render::RenderPath::kPlanar3d;
  s.planar3d = scene->pixel3d;
  auto configured = (*out)->configure(s);
  ASSERT_TRUE(configured) << configured.error().message;
  // A red quad behind the wall (lambda 1.5) and a green one in front (lambda 0.6) whose
  // viewer images overlap; drawn far-after-near so only the depth test can order them.
  render::ColoredMesh mesh;
  auto quad = [&](double a0, double b0, double a1, double b1, double lambda, cv::Vec4b col) {
    const int base = static_cast<int>(mesh.vertices.size());
    for (auto [a, b] : {std::pair{a0, b0}, {a1, b0}, {a1, b1}, {a0, b1}}) {
      mesh.vertices.push_back(scene->eye + lambda * (onS(scene->S, a, b) - scene->eye));
      mesh.colors.push_back(col);
    }
    mesh.triangles.push_back({base, base + 1, base + 2});
    mesh.triangles.push_back({base, base + 2, base + 3});
  };
  quad(0.45, 0.45, 0.6, 0.6, 0.6, {0, 255, 0, 255});
  quad(0.35, 0.35, 0.55, 0.55, 1.5, {255, 0, 0, 255});
  auto shown = (*out)->show({nullptr, &mesh, 1});
  ASSERT_TRUE(shown && *shown) << (shown ? "not rendered" : shown.error().message);
  const cv::Mat& f = (*out)->lastFrame();
  ASSERT_EQ(f.size(), cv::Size(kW, kH));
  auto pixelOf = [&](double a, double b) -> Vec2 {
    return (scene->P * onS(scene->S, a, b).homogeneous()).hnormalized();
  };
  const Vec2 overlap = pixelOf(0.5, 0.5), red_only = pixelOf(0.4, 0.4);
  const cv::Rect frame(0, 0, kW, kH);
  ASSERT_TRUE(frame.contains(cv::Point(int(overlap.x()), int(overlap.y()))));
  ASSERT_TRUE(frame.contains(cv::Point(int(red_only.x()), int(red_only.y()))));
  const cv::Vec4b at_overlap =
      f.at<cv::Vec4b>(int(std::lround(overlap.y())), int(std::lround(overlap.x())));
  const cv::Vec4b at_red =
      f.at<cv::Vec4b>(int(std::lround(red_only.y())), int(std::lround(red_only.x())));
  EXPECT_EQ(at_overlap, cv::Vec4b(0, 255, 0, 255));
  EXPECT_EQ(at_red, cv::Vec4b(255, 0, 0, 255));
  // The green quad's rendered area centroid against the centroid of its projected outline
  // (a quadrilateral: lines stay lines). Pixel-coverage quantisation of a region of
  // area A and perimeter L moves the centroid by ~L/(2A) px at most in the worst case.
  double sx = 0, sy = 0, n = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (f.at<cv::Vec4b>(y, x)[1] == 255) sx += x, sy += y, n += 1;
  ASSERT_GT(n, 1000);
  std::array<Vec2, 4> q = {pixelOf(0.45, 0.45), pixelOf(0.6, 0.45), pixelOf(0.6, 0.6),
                           pixelOf(0.45, 0.6)};
  double A = 0, cx = 0, cy = 0, L = 0;
  for (int i = 0; i < 4; ++i) {
    const Vec2 &p = q[i], &r = q[(i + 1) % 4];
    const double cr = p.x() * r.y() - r.x() * p.y();
    A += cr / 2;
    cx += (p.x() + r.x()) * cr;
    cy += (p.y() + r.y()) * cr;
    L += (r - p).norm();
  }
  cx /= 6 * A;
  cy /= 6 * A;
  const double tol = std::max(0.05, L / (2 * std::abs(A)));
  EXPECT_NEAR(sx / n, cx, tol);
  EXPECT_NEAR(sy / n, cy, tol);
  std::printf("green centroid error (%.4f, %.4f) px, tolerance %.4f\n", sx / n - cx, sy / n - cy,
              tol);
}

}  // namespace
}  // namespace procam::output
