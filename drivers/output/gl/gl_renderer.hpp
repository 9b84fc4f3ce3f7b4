#pragma once
// The GLES 3 back-end of render::Renderer: the same paths as the CPU reference, drawn by
// the GPU ([Raskar02] §3.2.3, §4.1.2-4.1.3, §4.2.1-4.2.3):
//  - homography pre-warp: one quad with projective texture coordinates;
//  - planar 3D: vertex-coloured triangles through A'4x4 P_T with the depth test;
//  - two-pass mesh: the surface mesh from the projector, the desired image projected on
//    it from the viewer (projective texture);
//  - lookup warp and post-rendering warp: textured triangles of a warp grid;
//  - final stage: alpha mask, weight LUT and output LUT in integer arithmetic.
// Needs a current GLES 3 context on the calling thread for its whole life; the owner of
// the context (drivers/output/egl) must destroy the renderer first.
#include <memory>

#include "core/error.hpp"
#include "gl/gl_objects.hpp"
#include "gl/gl_programs.hpp"
#include "render/gl_conventions.hpp"
#include "render/renderer.hpp"

namespace procam::output::gl {

// Where the final pass draws.
struct GlTarget {
  bool offscreen = true;   // own framebuffer object, read back with image row 0 first
  GLuint framebuffer = 0;  // when !offscreen: the window surface's framebuffer (usually 0)
};

class GlRenderer final : public render::Renderer {
 public:
  static Result<std::unique_ptr<GlRenderer>> create(GlTarget target);
  ~GlRenderer() override;

  const char* name() const override { return "gles3"; }
  Result<void> configure(const render::RenderSetup& setup) override;
  Result<bool> render(const render::Content& content) override;
  Result<void> readFrame(cv::Mat& out) override;
  void redraw() override { gate_.geometryChanged(); }

  // Copies the offscreen frame to `framebuffer` (a window surface's, usually 0) with image
  // row 0 at the top, as a display scans it out. kInvalidInput for a non-offscreen target.
  Result<void> blitTo(GLuint framebuffer);
  // Content uploads since creation (still content is uploaded once, not per frame).
  uint64_t uploads() const { return uploads_; }

 private:
  struct Stage {
    Texture color;
    Renderbuffer depth;
    Framebuffer fbo;
    cv::Size size;  // of the storage made; empty: none yet
    bool with_depth = false;
  };
  struct Geometry {
    VertexArray vao;
    Buffer vertices, indices;
    GLsizei count = 0;
    GLenum mode = GL_TRIANGLES;
    bool indexed = false;
  };

  explicit GlRenderer(GlTarget target) : target_(target) {}
  Result<void> makeStage(Stage& stage, cv::Size size, bool with_depth);
  Result<void> uploadContent(const cv::Mat& image, bool streaming);
  Result<void> upload3d(const render::ColoredMesh& mesh);
  void drawSampled(const SampleProgram& p, const Geometry& g, const Mat4& clip, const Mat4& tex,
                   GLuint source);
  void drawFinal(GLuint frame);

  GlTarget target_;
  Programs programs_;
  render::RenderSetup setup_;
  render::FrameGate gate_;
  bool configured_ = false;
  Texture content_;
  Stage stage_[2];
  Stage out_;
  Geometry main_, post_, quad_;
  Mat4 main_clip_ = Mat4::Identity(), main_tex_ = Mat4::Zero();
  Texture mask_, weight_lut_, output_lut_;
  bool final_stage_made_ = false;
  bool final_identity_ = false;  // the final stage changes nothing: skipped
  cv::Size main_quad_size_;      // the homography quad's output size in main_ (empty: none)
  cv::Size final_quad_size_;     // the final stage quad's
  // The content texture holds version `uploaded_` while content_valid_; the main geometry
  // holds the mesh of that version on the planar 3D path.
  cv::Size content_size_;
  bool content_valid_ = false;
  uint64_t uploaded_ = 0;
  uint64_t uploads_ = 0;
  uint64_t renders_ = 0;      // render() calls that drew
  uint64_t last_upload_ = 0;  // renders_ at the last upload
  Buffer unpack_[2];          // pixel-buffer objects for content that changes every frame
  size_t unpack_size_ = 0;
  int unpack_next_ = 0;
};

// Upper-left 3x3 of a 4x4 set to m, rest zero (mat3 uniforms carried in mat4 slots).
Mat4 embed3(const Mat3& m);

}  // namespace procam::output::gl
