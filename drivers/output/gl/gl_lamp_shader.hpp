#pragma once
// Shader-lamp frames shaded by the GPU ([Raskar02] §5.2.4, eq. 5.4). §5.2.4 splits the work
// in two: the projector's view of the object (which surface point, normal, distance and
// incidence each pixel meets) changes only with the rig or the object and is cast once on
// the CPU (lamps::castLampView, with the weights); the shading changes with every viewer
// move or texture frame. This uploads the view's per-pixel buffers once and runs the
// shading per pixel in a GLES 3 fragment program: the appearance (texture, virtual light,
// Blinn-Phong highlight for the eye), I = w · L · d² / (k · cos θ) and the inverse response
// into 8-bit code values — the same inputs and formula as lamps::lampFrame, evaluated in
// 32-bit floats instead of doubles (the frames agree to one code value, a rounding of a
// value that lands within 1e-4 of a half code).
// Needs a current GLES 3 context on the calling thread for its whole life. shade() and
// readFrame() leave GL_FRAMEBUFFER bound to 0 and texture unit 0 active; they change the
// viewport, the program, the textures bound to units 0-3 and the vertex array binding
// (0 after), and turn off depth test, blending, culling and the scissor test.
#include <memory>
#include <optional>

#include "core/error.hpp"
#include "gl/gl_objects.hpp"
#include "shader_lamps/appearance.hpp"
#include "shader_lamps/lamp_frame.hpp"

namespace procam::output::gl {

class GlLampShader {
 public:
  // kIo when the program does not build.
  static Result<std::unique_ptr<GlLampShader>> create();
  ~GlLampShader();
  GlLampShader(const GlLampShader&) = delete;
  GlLampShader& operator=(const GlLampShader&) = delete;

  // The projector's view, weights and photometry (as lamps::lampFrame takes them),
  // uploaded once per rig. kInvalidInput as lampFrame refuses them; kTooLarge over the
  // context's texture size.
  Result<void> setView(const lamps::LampFrameInput& lamp);
  // The look; its texture uploaded once per change. kInvalidInput for a bad material
  // (lamps::checkMaterial); kTooLarge over the context's texture size.
  Result<void> setMaterial(const lamps::Material& material);
  // Shades the frame for white level `white` and the viewer `eye` (none: no specular
  // part) into the shader's framebuffer. kInvalidInput before setView/setMaterial, or for
  // a white level that is not finite and positive or an eye that is not finite.
  Result<void> shade(double white, const std::optional<Vec3>& eye);
  // The last shaded frame read back, BGR CV_8UC3, image row 0 first. kInvalidInput when
  // no frame was shaded since the view was set.
  Result<void> readFrame(cv::Mat& bgr);
  // The frame's RGBA8 texture (image row 0 at texture row 0), for an output to show.
  GLuint frameTexture() const { return frame_.get(); }
  cv::Size size() const { return size_; }

 private:
  struct Uniforms {
    GLint point = -1, normal = -1, shade = -1, texture = -1;
    GLint has_texture = -1, albedo = -1, specular = -1, shininess = -1, has_light = -1, light = -1,
          ambient = -1, has_eye = -1, eye = -1, white = -1, gain = -1, inv_gamma = -1;
  };
  GlLampShader() = default;

  Program program_;
  Uniforms u_;
  VertexArray vao_;
  Texture point_, normal_, shade_, texture_, frame_;
  Framebuffer fbo_;
  cv::Size size_;
  bool has_view_ = false, has_material_ = false, shaded_ = false;
  lamps::LampPhotometry photometry_;
  lamps::Material material_;  // without its texture (uploaded)
  bool has_texture_ = false;
  GLint max_texture_ = 0;
};

}  // namespace procam::output::gl
