#include "gl/gl_renderer.hpp"

#include <array>
#include <cstring>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "render/projective_mesh.hpp"

namespace procam::output::gl {
namespace {

using render::glConventions;
using render::GlOrigin;

Result<void> glCheck(const char* what) {
  const GLenum e = glGetError();
  if (e == GL_NO_ERROR) return {};
  return fail(ErrorCode::kIo, std::string("GL error ") + std::to_string(e) + " in " + what);
}

void uniformMat4(GLint loc, const Mat4& m) {
  std::array<float, 16> f{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) f[c * 4 + r] = static_cast<float>(m(r, c));
  glUniformMatrix4fv(loc, 1, GL_FALSE, f.data());
}

void textureParams(GLint filter) {
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

Texture makeTexture2d(GLenum internal, GLenum format, cv::Size size, const void* data,
                      GLint filter) {
  Texture t = makeTexture();
  glBindTexture(GL_TEXTURE_2D, t.get());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(internal), size.width, size.height, 0, format,
               GL_UNSIGNED_BYTE, data);
  textureParams(filter);
  return t;
}

// Uploads interleaved float vertices; attribute k has sizes[k] floats at location k.
void setVertices(GLuint vao, GLuint vbo, const std::vector<float>& data,
                 const std::vector<int>& sizes) {
  glBindVertexArray(vao);
  glBindBuffer(GL_ARRAY_BUFFER, vbo);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(data.size() * sizeof(float)), data.data(),
               GL_STATIC_DRAW);
  int stride = 0;
  for (int s : sizes) stride += s;
  int offset = 0;
  for (size_t k = 0; k < sizes.size(); ++k) {
    glEnableVertexAttribArray(static_cast<GLuint>(k));
    glVertexAttribPointer(static_cast<GLuint>(k), sizes[k], GL_FLOAT, GL_FALSE,
                          stride * static_cast<GLsizei>(sizeof(float)),
                          reinterpret_cast<const void*>(offset * sizeof(float)));
    offset += sizes[k];
  }
  // Attributes left enabled by an earlier layout of this array would read past the data.
  for (GLuint k = static_cast<GLuint>(sizes.size()); k < 4; ++k) glDisableVertexAttribArray(k);
}

void setIndices(GLuint vao, GLuint ebo, const std::vector<GLuint>& idx) {
  glBindVertexArray(vao);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(idx.size() * sizeof(GLuint)),
               idx.data(), GL_STATIC_DRAW);
}

// Full-frame quad over pixel edges (-0.5 .. size - 0.5) with per-corner source
// coordinates `source(corner)` (homogeneous, 3 floats).
template <class F>
std::vector<float> quadVertices(cv::Size size, F source) {
  const double x0 = -0.5, y0 = -0.5, x1 = size.width - 0.5, y1 = size.height - 0.5;
  const std::array<Vec2, 4> corners = {Vec2(x0, y0), Vec2(x1, y0), Vec2(x0, y1), Vec2(x1, y1)};
  std::vector<float> v;
  for (const Vec2& c : corners) {
    const Vec3 s = source(c);
    v.insert(v.end(), {float(c.x()), float(c.y()), float(s.x()), float(s.y()), float(s.z())});
  }
  return v;
}

// Grid triangles with the CPU's split (render/warp_map.hpp): (00, 10, 11) and (00, 11, 01).
void gridGeometry(const render::WarpGrid& g, std::vector<float>& v, std::vector<GLuint>& idx) {
  for (int j = 0; j < g.rows; ++j) {
    for (int i = 0; i < g.cols; ++i) {
      const Vec2 n = g.node(i, j), s = g.at(i, j);
      v.insert(v.end(), {float(n.x()), float(n.y()), float(s.x()), float(s.y()), 1.0f});
    }
  }
  for (int j = 0; j + 1 < g.rows; ++j) {
    for (int i = 0; i + 1 < g.cols; ++i) {
      const GLuint a = static_cast<GLuint>(j * g.cols + i), b = a + 1;
      const GLuint c = a + static_cast<GLuint>(g.cols), d = c + 1;
      // A triangle with a node no source reaches is not drawn, as on the CPU.
      auto reached = [&](GLuint k) { return g.source[k].x() != render::kOutside; };
      if (reached(a) && reached(b) && reached(d)) idx.insert(idx.end(), {a, b, d});
      if (reached(a) && reached(d) && reached(c)) idx.insert(idx.end(), {a, d, c});
    }
  }
}

}  // namespace

Mat4 embed3(const Mat3& m) {
  Mat4 out = Mat4::Zero();
  out.topLeftCorner<3, 3>() = m;
  return out;
}

Result<std::unique_ptr<GlRenderer>> GlRenderer::create(GlTarget target) {
  std::unique_ptr<GlRenderer> r(new GlRenderer(target));
  auto programs = buildPrograms();
  if (!programs) return tl::unexpected(programs.error());
  r->programs_ = std::move(*programs);
  for (Geometry* g : {&r->main_, &r->post_, &r->quad_}) {
    g->vao = makeVertexArray();
    g->vertices = makeBuffer();
    g->indices = makeBuffer();
  }
  if (auto ok = glCheck("GlRenderer::create"); !ok) return tl::unexpected(ok.error());
  return r;
}

GlRenderer::~GlRenderer() = default;

Result<void> GlRenderer::makeStage(Stage& stage, cv::Size size, bool with_depth) {
  if (stage.fbo && stage.size == size && stage.with_depth == with_depth) return {};
  stage.size = {};
  stage.color = makeTexture2d(GL_RGBA8, GL_RGBA, size, nullptr, GL_LINEAR);
  stage.fbo = makeFramebuffer();
  glBindFramebuffer(GL_FRAMEBUFFER, stage.fbo.get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, stage.color.get(), 0);
  stage.depth.reset();
  if (with_depth) {
    stage.depth = makeRenderbuffer();
    glBindRenderbuffer(GL_RENDERBUFFER, stage.depth.get());
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, size.width, size.height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                              stage.depth.get());
  }
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    return fail(ErrorCode::kIo, "GL framebuffer incomplete");
  }
  if (auto ok = glCheck("makeStage"); !ok) return ok;
  stage.size = size;
  stage.with_depth = with_depth;
  return {};
}

Result<void> GlRenderer::configure(const render::RenderSetup& setup) {
  if (auto ok = render::validateSetup(setup); !ok) return ok;
  // The planar 3D path's mesh lives in the main geometry, which other paths overwrite.
  if (!configured_ || (setup_.path == render::RenderPath::kPlanar3d) !=
                          (setup.path == render::RenderPath::kPlanar3d)) {
    content_valid_ = false;
  }
  configured_ = false;  // until every object matches the new setup
  const cv::Size out = setup.output_size;
  const bool depth =
      setup.path == render::RenderPath::kTwoPassMesh || setup.path == render::RenderPath::kPlanar3d;
  if (auto ok = makeStage(stage_[0], out, depth); !ok) return ok;
  if (setup.post_warp) {
    if (auto ok = makeStage(stage_[1], out, false); !ok) return ok;
  }
  if (target_.offscreen) {
    if (auto ok = makeStage(out_, out, depth); !ok) return ok;
  }
  const Mat4 clip = glConventions(out.width, out.height, GlOrigin::kRow0AtGlBottom).clip_from_pixel;
  const Mat3 tex =
      glConventions(setup.content_size.width, setup.content_size.height, GlOrigin::kRow0AtGlBottom)
          .tex_from_pixel;
  main_.indexed = false;
  main_.mode = GL_TRIANGLES;
  switch (setup.path) {
    case render::RenderPath::kHomography: {
      const Mat3 Hinv = setup.homography.inverse();
      if (!Hinv.allFinite()) return fail(ErrorCode::kDegenerate, "gl: singular homography");
      const double scale = 1.0 / Hinv.cwiseAbs().maxCoeff();
      // The quad carries output pixels; H^-1 is a uniform, so that a keystone that moves
      // every frame writes no vertex buffer the GPU may still be reading.
      if (main_quad_size_ != out) {
        setVertices(main_.vao.get(), main_.vertices.get(),
                    quadVertices(out, [](const Vec2& c) { return Vec3(c.x(), c.y(), 1.0); }),
                    {2, 3});
        main_quad_size_ = out;
      }
      main_.mode = GL_TRIANGLE_STRIP;
      main_.count = 4;
      main_clip_ = clip;
      main_tex_ = embed3(tex * (scale * Hinv));
      break;
    }
    case render::RenderPath::kLookupWarp: {
      main_quad_size_ = {};
      std::vector<float> v;
      std::vector<GLuint> idx;
      gridGeometry(setup.lookup, v, idx);
      setVertices(main_.vao.get(), main_.vertices.get(), v, {2, 3});
      setIndices(main_.vao.get(), main_.indices.get(), idx);
      main_.indexed = true;
      main_.count = static_cast<GLsizei>(idx.size());
      main_clip_ = clip;
      main_tex_ = embed3(tex);
      break;
    }
    case render::RenderPath::kTwoPassMesh: {
      main_quad_size_ = {};
      // Same coverage as the CPU map: triangles with a vertex behind the projector are dropped.
      std::vector<float> v;
      for (const Vec3& p : setup.surface.vertices) {
        v.insert(v.end(), {float(p.x()), float(p.y()), float(p.z())});
      }
      std::vector<GLuint> idx;
      double near = INFINITY, far = 0;
      for (const auto& t : setup.surface.triangles) {
        bool front = true;
        for (int i : t) {
          if (i < 0 || i >= static_cast<int>(setup.surface.vertices.size())) {
            return fail(ErrorCode::kInvalidInput, "gl: mesh index out of range");
          }
          front = front && setup.projector.row(2).dot(setup.surface.vertices[i].homogeneous()) > 0;
        }
        if (!front) continue;
        for (int i : t) {
          const double w = setup.projector.row(2).dot(setup.surface.vertices[i].homogeneous());
          near = std::min(near, w);
          far = std::max(far, w);
          idx.push_back(static_cast<GLuint>(i));
        }
      }
      if (idx.empty())
        return fail(ErrorCode::kInvalidInput, "gl: no triangle in front of projector");
      // Depth-buffer range: a near plane at a tiny depth would squeeze every depth onto
      // 1.0 in float and 24 bits. Surface points closer than far/1000 lie in the
      // projector's own plane, outside any practical field of view, and may be clipped.
      near = std::max(0.5 * near, 1e-3 * far);
      auto depth4 = render::pixelProjectionWithDepth(setup.projector, near, 2.0 * far);
      if (!depth4) return tl::unexpected(depth4.error());
      setVertices(main_.vao.get(), main_.vertices.get(), v, {3});
      setIndices(main_.vao.get(), main_.indices.get(), idx);
      main_.indexed = true;
      main_.count = static_cast<GLsizei>(idx.size());
      main_clip_ = clip * *depth4;
      main_tex_ = Mat4::Zero();
      main_tex_.topRows<3>() = tex * setup.viewer;
      // Keep magnitudes near 1 for float uniforms; (s, t, q) is scale-free.
      main_tex_ /= main_tex_.cwiseAbs().maxCoeff();
      break;
    }
    case render::RenderPath::kPlanar3d:
      main_quad_size_ = {};
      main_clip_ = clip * setup.planar3d;  // geometry arrives with the content
      break;
    case render::RenderPath::kShaderLamps:  // refused by validateSetup above
      return fail(ErrorCode::kInvalidInput, "GL renderer: shader-lamps frames come drawn");
  }
  if (setup.post_warp) {
    std::vector<float> v;
    std::vector<GLuint> idx;
    gridGeometry(*setup.post_warp, v, idx);
    setVertices(post_.vao.get(), post_.vertices.get(), v, {2, 3});
    setIndices(post_.vao.get(), post_.indices.get(), idx);
    post_.indexed = true;
    post_.count = static_cast<GLsizei>(idx.size());
  }
  if (final_quad_size_ != out) {
    setVertices(quad_.vao.get(), quad_.vertices.get(),
                quadVertices(out, [](const Vec2&) { return Vec3::Zero(); }), {2, 3});
    quad_.mode = GL_TRIANGLE_STRIP;
    quad_.count = 4;
    final_quad_size_ = out;
  }
  // Final stage textures: mask (1x1 unused when absent) and LUTs, fetched texel by texel;
  // made again only when the stage changed (a moving keystone keeps its blend).
  const auto& fs = setup.final_stage;
  if (!final_stage_made_ || !render::sameStage(fs, setup_.final_stage)) {
    const uint8_t one = 255;
    mask_ = fs.alpha.empty() ? makeTexture2d(GL_R8, GL_RED, {1, 1}, &one, GL_NEAREST)
                             : makeTexture2d(GL_R8, GL_RED, fs.alpha.size(),
                                             cv::Mat(fs.alpha.clone()).data, GL_NEAREST);
    weight_lut_ = makeTexture2d(GL_R8, GL_RED, {256, 1}, fs.weight_lut.data(), GL_NEAREST);
    std::vector<uint8_t> lut(256 * 4, 255);
    for (int i = 0; i < 256; ++i)
      for (int c = 0; c < 3; ++c) lut[4 * i + c] = fs.output_lut[c][i];
    output_lut_ = makeTexture2d(GL_RGBA8, GL_RGBA, {256, 1}, lut.data(), GL_NEAREST);
    final_stage_made_ = true;
    final_identity_ = fs.isIdentity();
  }
  // Still content stays on the GPU across geometry changes: the texture is made again
  // (and the content uploaded again) only when the content size changes.
  if (setup.path != render::RenderPath::kPlanar3d &&
      (!content_ || content_size_ != setup.content_size)) {
    content_ = makeTexture2d(GL_RGBA8, GL_RGBA, setup.content_size, nullptr, GL_LINEAR);
    content_size_ = setup.content_size;
    content_valid_ = false;
  }
  if (auto ok = glCheck("GlRenderer::configure"); !ok) return ok;
  setup_ = setup;
  configured_ = true;
  gate_.geometryChanged();
  return {};
}

Result<void> GlRenderer::uploadContent(const cv::Mat& image, bool streaming) {
  if (image.type() != CV_8UC4 || image.size() != setup_.content_size || image.step % 4 != 0) {
    return fail(ErrorCode::kInvalidInput, "gl: content must be CV_8UC4 of content_size");
  }
  glBindTexture(GL_TEXTURE_2D, content_.get());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  if (!streaming) {
    glPixelStorei(GL_UNPACK_ROW_LENGTH, static_cast<GLint>(image.step / 4));
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, image.cols, image.rows, GL_RGBA, GL_UNSIGNED_BYTE,
                    image.data);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    return glCheck("upload content");
  }
  // Content that changes every frame (video): copied into one of two pixel-buffer objects,
  // orphaned first, so the texture transfer runs asynchronously while the previous one
  // may still be read.
  const size_t row = static_cast<size_t>(image.cols) * 4, size = row * image.rows;
  if (!unpack_[0] || unpack_size_ != size) {
    for (Buffer& b : unpack_) b = makeBuffer();
    unpack_size_ = size;
  }
  const Buffer& pbo = unpack_[unpack_next_];
  unpack_next_ ^= 1;
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, pbo.get());
  glBufferData(GL_PIXEL_UNPACK_BUFFER, static_cast<GLsizeiptr>(size), nullptr, GL_STREAM_DRAW);
  auto* dst = static_cast<uint8_t*>(
      glMapBufferRange(GL_PIXEL_UNPACK_BUFFER, 0, static_cast<GLsizeiptr>(size),
                       GL_MAP_WRITE_BIT | GL_MAP_INVALIDATE_BUFFER_BIT));
  if (!dst) {
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    return fail(ErrorCode::kIo, "gl: cannot map the pixel-buffer object");
  }
  if (image.isContinuous()) {
    std::memcpy(dst, image.data, size);
  } else {
    for (int y = 0; y < image.rows; ++y) std::memcpy(dst + y * row, image.ptr(y), row);
  }
  glUnmapBuffer(GL_PIXEL_UNPACK_BUFFER);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, image.cols, image.rows, GL_RGBA, GL_UNSIGNED_BYTE,
                  nullptr);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  return glCheck("stream content");
}

Result<void> GlRenderer::upload3d(const render::ColoredMesh& mesh) {
  if (mesh.colors.size() != mesh.vertices.size()) {
    return fail(ErrorCode::kInvalidInput, "gl: one colour per vertex required");
  }
  std::vector<float> v;
  v.reserve(mesh.vertices.size() * 7);
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& p = mesh.vertices[i];
    const cv::Vec4b& c = mesh.colors[i];
    v.insert(v.end(), {float(p.x()), float(p.y()), float(p.z()), c[0] / 255.0f, c[1] / 255.0f,
                       c[2] / 255.0f, c[3] / 255.0f});
  }
  std::vector<GLuint> idx;
  for (const auto& t : mesh.triangles) {
    for (int i : t) {
      if (i < 0 || i >= static_cast<int>(mesh.vertices.size())) {
        return fail(ErrorCode::kInvalidInput, "gl: mesh index out of range");
      }
      idx.push_back(static_cast<GLuint>(i));
    }
  }
  setVertices(main_.vao.get(), main_.vertices.get(), v, {3, 4});
  setIndices(main_.vao.get(), main_.indices.get(), idx);
  main_.indexed = true;
  main_.count = static_cast<GLsizei>(idx.size());
  return glCheck("upload 3D content");
}

void GlRenderer::drawSampled(const SampleProgram& p, const Geometry& g, const Mat4& clip,
                             const Mat4& tex, GLuint source) {
  glUseProgram(p.program.get());
  uniformMat4(p.clip, clip);
  uniformMat4(p.tex, tex);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, source);
  glUniform1i(p.source, 0);
  glBindVertexArray(g.vao.get());
  if (g.indexed) {
    glDrawElements(g.mode, g.count, GL_UNSIGNED_INT, nullptr);
  } else {
    glDrawArrays(g.mode, 0, g.count);
  }
}

void GlRenderer::drawFinal(GLuint frame) {
  const cv::Size out = setup_.output_size;
  const GLuint fbo = target_.offscreen ? out_.fbo.get() : target_.framebuffer;
  const auto origin = target_.offscreen ? GlOrigin::kRow0AtGlBottom : GlOrigin::kRow0AtGlTop;
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, out.width, out.height);
  glDisable(GL_DEPTH_TEST);
  const auto& p = programs_.final_stage;
  glUseProgram(p.program.get());
  uniformMat4(p.clip, glConventions(out.width, out.height, origin).clip_from_pixel);
  const std::array<std::pair<GLint, GLuint>, 4> units = {{{p.frame, frame},
                                                          {p.mask, mask_.get()},
                                                          {p.weight_lut, weight_lut_.get()},
                                                          {p.output_lut, output_lut_.get()}}};
  for (size_t k = 0; k < units.size(); ++k) {
    glActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(k));
    glBindTexture(GL_TEXTURE_2D, units[k].second);
    glUniform1i(units[k].first, static_cast<GLint>(k));
  }
  glUniform1i(p.has_mask, setup_.final_stage.alpha.empty() ? 0 : 1);
  glBindVertexArray(quad_.vao.get());
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  glActiveTexture(GL_TEXTURE0);
}

Result<bool> GlRenderer::render(const render::Content& content) {
  if (!configured_) return fail(ErrorCode::kInvalidInput, "gl renderer: not configured");
  const bool is3d = setup_.path == render::RenderPath::kPlanar3d;
  if (is3d ? content.mesh == nullptr : content.image == nullptr) {
    return fail(ErrorCode::kInvalidInput, "gl renderer: content missing for the render path");
  }
  if (!gate_.needsRender(content.version)) return false;
  ++renders_;
  if (!content_valid_ || content.version != uploaded_) {
    // Consecutive frames with new content: a stream; a change after still frames: one upload.
    const bool streaming = content_valid_ && last_upload_ + 1 == renders_;
    if (auto ok = is3d ? upload3d(*content.mesh) : uploadContent(*content.image, streaming); !ok) {
      content_valid_ = false;
      return tl::unexpected(ok.error());
    }
    content_valid_ = true;
    uploaded_ = content.version;
    last_upload_ = renders_;
    ++uploads_;
  }
  // A large mesh's upload is the long CPU step before the draw: ask once more here.
  if (content.stop && content.stop()) return fail(ErrorCode::kCancelled, "gl renderer: stopped");
  const cv::Size out = setup_.output_size;
  // Without blending, LUTs or a post-render warp the final stage is the identity: the main
  // pass draws straight into the frame, one full-frame pass instead of two (a GPU with few
  // raster units, as an H100's, spends ~0.45 ms on each at 1080p).
  const bool direct = target_.offscreen && !setup_.post_warp && final_identity_;
  glBindFramebuffer(GL_FRAMEBUFFER, direct ? out_.fbo.get() : stage_[0].fbo.get());
  glViewport(0, 0, out.width, out.height);
  glClearColor(0, 0, 0, 0);
  glClearDepthf(1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  const bool depth = is3d || setup_.path == render::RenderPath::kTwoPassMesh;
  if (depth) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
  } else {
    glDisable(GL_DEPTH_TEST);
  }
  if (is3d) {
    glUseProgram(programs_.color.program.get());
    uniformMat4(programs_.color.clip, main_clip_);
    glBindVertexArray(main_.vao.get());
    glDrawElements(GL_TRIANGLES, main_.count, GL_UNSIGNED_INT, nullptr);
  } else {
    const SampleProgram& p = setup_.path == render::RenderPath::kTwoPassMesh ? programs_.sample_mesh
                                                                             : programs_.sample_2d;
    drawSampled(p, main_, main_clip_, main_tex_, content_.get());
  }
  glDisable(GL_DEPTH_TEST);
  if (direct) {
    if (auto ok = glCheck("GlRenderer::render"); !ok) return tl::unexpected(ok.error());
    gate_.rendered(content.version);
    return true;
  }
  GLuint last = stage_[0].color.get();
  if (setup_.post_warp) {
    glBindFramebuffer(GL_FRAMEBUFFER, stage_[1].fbo.get());
    glClear(GL_COLOR_BUFFER_BIT);
    const auto c = glConventions(out.width, out.height, GlOrigin::kRow0AtGlBottom);
    drawSampled(programs_.sample_2d, post_, c.clip_from_pixel, embed3(c.tex_from_pixel), last);
    last = stage_[1].color.get();
  }
  drawFinal(last);
  if (auto ok = glCheck("GlRenderer::render"); !ok) return tl::unexpected(ok.error());
  gate_.rendered(content.version);
  return true;
}

Result<void> GlRenderer::blitTo(GLuint framebuffer) {
  if (!configured_ || !target_.offscreen) {
    return fail(ErrorCode::kInvalidInput, "gl renderer: blit needs a configured offscreen frame");
  }
  const cv::Size s = setup_.output_size;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, out_.fbo.get());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, framebuffer);
  // The offscreen frame holds image row 0 at GL's bottom, a window at its top.
  glBlitFramebuffer(0, 0, s.width, s.height, 0, s.height, s.width, 0, GL_COLOR_BUFFER_BIT,
                    GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return glCheck("blit to the window");
}

Result<void> GlRenderer::readFrame(cv::Mat& out) {
  if (!configured_) return fail(ErrorCode::kInvalidInput, "gl renderer: not configured");
  const cv::Size size = setup_.output_size;
  out.create(size, CV_8UC4);
  glBindFramebuffer(GL_FRAMEBUFFER, target_.offscreen ? out_.fbo.get() : target_.framebuffer);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  cv::Mat tight = out.isContinuous() ? out : cv::Mat(size, CV_8UC4);
  glReadPixels(0, 0, size.width, size.height, GL_RGBA, GL_UNSIGNED_BYTE, tight.data);
  if (auto ok = glCheck("glReadPixels"); !ok) return ok;
  // Window surfaces hold image row 0 at the top (GL's last row).
  if (!target_.offscreen) cv::flip(tight, tight, 0);
  if (tight.data != out.data) tight.copyTo(out);
  return {};
}

}  // namespace procam::output::gl
