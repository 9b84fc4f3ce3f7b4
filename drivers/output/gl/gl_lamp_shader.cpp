#include "gl/gl_lamp_shader.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "gl/gl_programs.hpp"

namespace procam::output::gl {
namespace {

// One triangle over the whole framebuffer, from the vertex index alone.
constexpr const char* kFullFrameVs = R"(#version 300 es
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)";

// lamps::desiredRadiance and lamps::lampFrame per pixel ([Raskar02] eq. 5.1 as §5.2.4
// splits it, eq. 5.4), the texture read as lamps::textureAt reads it (bilinear between
// texel centres, clamped to the edge, v up).
constexpr const char* kShadeFs = R"(#version 300 es
precision highp float;
precision highp int;
uniform highp sampler2D uPoint;    // world point
uniform highp sampler2D uNormal;   // unit shading normal
uniform highp sampler2D uShade;    // s, t, w d^2 / cos(theta) (0: the pixel lights nothing)
uniform highp sampler2D uTexture;  // linear RGB
uniform bool uHasTexture, uHasLight, uHasEye;
uniform vec3 uAlbedo, uSpecular, uLight, uEye, uGain;
uniform float uShininess, uAmbient, uWhite, uInvGamma;
out vec4 oColor;

vec3 texel(ivec2 p, ivec2 size) {
  return texelFetch(uTexture, clamp(p, ivec2(0), size - 1), 0).rgb;
}

vec3 textureAt(vec2 uv) {
  if (!uHasTexture) return vec3(1.0);
  ivec2 size = textureSize(uTexture, 0);
  vec2 c = clamp(uv, 0.0, 1.0);
  vec2 xy = vec2(c.x * float(size.x), (1.0 - c.y) * float(size.y)) - 0.5;
  vec2 f = floor(xy);
  vec2 a = xy - f;
  ivec2 p = ivec2(f);
  return (1.0 - a.y) * ((1.0 - a.x) * texel(p, size) + a.x * texel(p + ivec2(1, 0), size)) +
         a.y * ((1.0 - a.x) * texel(p + ivec2(0, 1), size) + a.x * texel(p + ivec2(1, 1), size));
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 s = texelFetch(uShade, p, 0);
  if (!(s.z > 0.0)) { oColor = vec4(0.0, 0.0, 0.0, 1.0); return; }
  vec3 n = texelFetch(uNormal, p, 0).xyz;
  vec3 L = uAlbedo * textureAt(s.xy);
  if (uHasLight) L *= uAmbient + (1.0 - uAmbient) * max(0.0, dot(n, uLight));
  if (uHasEye) {
    vec3 toEye = normalize(uEye - texelFetch(uPoint, p, 0).xyz);
    vec3 halfway = toEye + (uHasLight ? uLight : toEye);
    float len = length(halfway);
    float c = len > 0.0 ? max(0.0, dot(n, halfway / len)) : 0.0;
    L += (c > 0.0 ? pow(c, uShininess) : 0.0) * uSpecular;
  }
  vec3 I = clamp(uWhite * s.z * L / uGain, 0.0, 1.0);
  vec3 code = floor(255.0 * pow(I, vec3(uInvGamma)) + 0.5);
  oColor = vec4(code / 255.0, 1.0);
}
)";

Result<void> glStatus(const char* what) {
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    return fail(ErrorCode::kIo, std::string(what) + ": GL error " + std::to_string(e));
  return {};
}

// A float texture for texelFetch (never filtered: 32-bit float textures need not be
// filterable in GLES 3), from CV_32FC4 data with row 0 first.
void uploadFloat4(Texture& t, const cv::Mat& rgba) {
  if (!t) t = makeTexture();
  glBindTexture(GL_TEXTURE_2D, t.get());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, rgba.cols, rgba.rows, 0, GL_RGBA, GL_FLOAT,
               rgba.ptr());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

cv::Mat withFourth(const cv::Mat& three) {
  cv::Mat four;
  cv::cvtColor(three, four, cv::COLOR_RGB2RGBA);
  return four;
}

void setVec3(GLint at, const Vec3& v) {
  glUniform3f(at, static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()));
}

}  // namespace

Result<std::unique_ptr<GlLampShader>> GlLampShader::create() {
  std::unique_ptr<GlLampShader> s(new GlLampShader());
  auto p = linkProgram(kFullFrameVs, kShadeFs);
  if (!p) return tl::unexpected(p.error());
  const GLuint id = p->get();
  const auto at = [id](const char* name) { return glGetUniformLocation(id, name); };
  s->u_ = {at("uPoint"),      at("uNormal"), at("uShade"),    at("uTexture"),
           at("uHasTexture"), at("uAlbedo"), at("uSpecular"), at("uShininess"),
           at("uHasLight"),   at("uLight"),  at("uAmbient"),  at("uHasEye"),
           at("uEye"),        at("uWhite"),  at("uGain"),     at("uInvGamma")};
  s->program_ = std::move(*p);
  s->vao_ = makeVertexArray();
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &s->max_texture_);
  if (auto ok = glStatus("building the shader-lamp program"); !ok)
    return tl::unexpected(ok.error());
  return s;
}

GlLampShader::~GlLampShader() = default;

Result<void> GlLampShader::setView(const lamps::LampFrameInput& lamp) {
  if (auto ok = lamps::checkLampInput(lamp); !ok) return ok;
  const lamps::LampView& v = *lamp.view;
  if (v.size.width > max_texture_ || v.size.height > max_texture_)
    return fail(ErrorCode::kTooLarge, "the projector's frame is larger than the GPU's textures");
  // w d^2 / cos(theta) in double, as lampFrame forms it, with the texture coordinate.
  cv::Mat shade(v.size, CV_32FC4, cv::Scalar::all(0));
  for (int y = 0; y < v.size.height; ++y) {
    for (int x = 0; x < v.size.width; ++x) {
      const double w = lamp.weight->at<float>(y, x);
      if (!(w > 0)) continue;
      const double d = v.distance.at<float>(y, x), c = v.cosine.at<float>(y, x);
      const double scale = w * d * d / c;
      const cv::Vec2f t = v.texcoord.at<cv::Vec2f>(y, x);
      shade.at<cv::Vec4f>(y, x) = {std::isfinite(t[0]) ? t[0] : 0.f,
                                   std::isfinite(t[1]) ? t[1] : 0.f,
                                   std::isfinite(scale) ? static_cast<float>(scale) : 3e38f, 0.f};
    }
  }
  uploadFloat4(point_, withFourth(v.point));
  uploadFloat4(normal_, withFourth(v.normal));
  uploadFloat4(shade_, shade);
  if (size_ != v.size) {
    frame_ = makeTexture();
    glBindTexture(GL_TEXTURE_2D, frame_.get());
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, v.size.width, v.size.height);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    fbo_ = makeFramebuffer();
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, frame_.get(), 0);
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      has_view_ = false;
      size_ = {};
      return fail(ErrorCode::kIo, "the shader-lamp framebuffer is incomplete");
    }
    size_ = v.size;
  }
  photometry_ = lamp.photometry;
  shaded_ = false;
  if (auto ok = glStatus("uploading a projector's view"); !ok) {
    has_view_ = false;
    return ok;
  }
  has_view_ = true;
  return {};
}

Result<void> GlLampShader::setMaterial(const lamps::Material& material) {
  if (auto ok = lamps::checkMaterial(material); !ok) return ok;
  const cv::Mat& tex = material.texture;
  if (tex.cols > max_texture_ || tex.rows > max_texture_)
    return fail(ErrorCode::kTooLarge, "the texture is larger than the GPU's textures");
  if (!tex.empty()) uploadFloat4(texture_, withFourth(tex.isContinuous() ? tex : tex.clone()));
  material_ = material;
  material_.texture = cv::Mat();
  has_texture_ = !tex.empty();
  if (auto ok = glStatus("uploading a texture"); !ok) {
    has_material_ = false;
    return ok;
  }
  has_material_ = true;
  return {};
}

Result<void> GlLampShader::shade(double white, const std::optional<Vec3>& eye) {
  if (!has_view_ || !has_material_)
    return fail(ErrorCode::kInvalidInput, "a frame needs a projector's view and a material");
  if (!(std::isfinite(white) && white > 0))
    return fail(ErrorCode::kInvalidInput, "the white level must be finite and positive");
  if (eye && !eye->allFinite()) return fail(ErrorCode::kInvalidInput, "the eye is not finite");
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
  glViewport(0, 0, size_.width, size_.height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glDisable(GL_SCISSOR_TEST);
  glUseProgram(program_.get());
  const Texture* units[] = {&point_, &normal_, &shade_, &texture_};
  const GLint samplers[] = {u_.point, u_.normal, u_.shade, u_.texture};
  for (int i = 0; i < 4; ++i) {
    glActiveTexture(GL_TEXTURE0 + i);
    glBindTexture(GL_TEXTURE_2D, units[i]->get());
    glUniform1i(samplers[i], i);
  }
  const lamps::Material& m = material_;
  glUniform1i(u_.has_texture, has_texture_);
  setVec3(u_.albedo, m.albedo_rgb);
  setVec3(u_.specular, m.specular_rgb);
  glUniform1f(u_.shininess, static_cast<float>(m.shininess));
  glUniform1i(u_.has_light, m.light_dir.has_value());
  setVec3(u_.light, m.light_dir ? Vec3(m.light_dir->normalized()) : Vec3::UnitZ());
  glUniform1f(u_.ambient, static_cast<float>(m.ambient));
  glUniform1i(u_.has_eye, eye && !m.specular_rgb.isZero());
  setVec3(u_.eye, eye.value_or(Vec3::Zero()));
  glUniform1f(u_.white, static_cast<float>(white));
  setVec3(u_.gain, photometry_.gain_rgb);
  glUniform1f(u_.inv_gamma, static_cast<float>(1 / photometry_.gamma));
  glBindVertexArray(vao_.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glActiveTexture(GL_TEXTURE0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (auto ok = glStatus("shading a shader-lamp frame"); !ok) return ok;
  shaded_ = true;
  return {};
}

Result<void> GlLampShader::readFrame(cv::Mat& bgr) {
  if (!has_view_ || !shaded_)
    return fail(ErrorCode::kInvalidInput, "no frame has been shaded for this view");
  cv::Mat rgba(size_, CV_8UC4);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, size_.width, size_.height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.ptr());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (auto ok = glStatus("reading a shader-lamp frame back"); !ok) return ok;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  return {};
}

}  // namespace procam::output::gl
