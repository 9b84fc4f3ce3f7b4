#include "gl/gl_programs.hpp"

#include <string>

namespace procam::output::gl {
namespace {

constexpr const char* kSample2dVs = R"(#version 300 es
layout(location = 0) in vec2 aPixel;
layout(location = 1) in vec3 aSource;
uniform mat4 uClip;
uniform mat4 uTex;
out vec3 vStq;
void main() {
  gl_Position = uClip * vec4(aPixel, 0.0, 1.0);
  vStq = (uTex * vec4(aSource, 0.0)).xyz;
}
)";

// Projective texture from the viewer onto the surface ([Raskar02] §3.2.3): (s, t, q) is linear
// in the world point, so GL's perspective-correct interpolation reproduces it exactly.
constexpr const char* kSampleMeshVs = R"(#version 300 es
layout(location = 0) in vec3 aWorld;
uniform mat4 uClip;
uniform mat4 uTex;
out vec3 vStq;
void main() {
  vec4 X = vec4(aWorld, 1.0);
  gl_Position = uClip * X;
  vStq = (uTex * X).xyz;
}
)";

constexpr const char* kSampleFs = R"(#version 300 es
precision highp float;
uniform sampler2D uSource;
in vec3 vStq;
out vec4 oColor;
void main() {
  if (vStq.z <= 0.0) { oColor = vec4(0.0); return; }
  vec2 st = vStq.xy / vStq.z;
  if (st.x < 0.0 || st.y < 0.0 || st.x >= 1.0 || st.y >= 1.0) { oColor = vec4(0.0); return; }
  oColor = texture(uSource, st);
}
)";

constexpr const char* kColorVs = R"(#version 300 es
layout(location = 0) in vec3 aWorld;
layout(location = 1) in vec4 aColor;
uniform mat4 uClip;
out vec4 vColor;
void main() {
  gl_Position = uClip * vec4(aWorld, 1.0);
  vColor = aColor;
}
)";

constexpr const char* kColorFs = R"(#version 300 es
precision highp float;
in vec4 vColor;
out vec4 oColor;
void main() { oColor = vColor; }
)";

constexpr const char* kFinalVs = R"(#version 300 es
layout(location = 0) in vec2 aPixel;
uniform mat4 uClip;
out vec2 vPixel;
void main() {
  gl_Position = uClip * vec4(aPixel, 0.0, 1.0);
  vPixel = aPixel;
}
)";

constexpr const char* kFinalFs = R"(#version 300 es
precision highp float;
precision highp int;
uniform sampler2D uFrame;
uniform sampler2D uMask;
uniform sampler2D uWeightLut;
uniform sampler2D uOutputLut;
uniform bool uHasMask;
in vec2 vPixel;
out vec4 oColor;
int code(float v) { return int(floor(v * 255.0 + 0.5)); }
void main() {
  ivec2 p = ivec2(floor(vPixel + 0.5));
  vec4 c = texelFetch(uFrame, p, 0);
  int a = uHasMask ? code(texelFetch(uMask, p, 0).r) : 255;
  int w = code(texelFetch(uWeightLut, ivec2(a, 0), 0).r);
  ivec3 v = (ivec3(code(c.r), code(c.g), code(c.b)) * w + 127) / 255;
  oColor = vec4(texelFetch(uOutputLut, ivec2(v.r, 0), 0).r,
                texelFetch(uOutputLut, ivec2(v.g, 0), 0).g,
                texelFetch(uOutputLut, ivec2(v.b, 0), 0).b, c.a);
}
)";

Result<Shader> compile(GLenum type, const char* src) {
  Shader s(glCreateShader(type));
  glShaderSource(s.get(), 1, &src, nullptr);
  glCompileShader(s.get());
  GLint ok = 0;
  glGetShaderiv(s.get(), GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetShaderInfoLog(s.get(), sizeof(log), nullptr, log);
    return fail(ErrorCode::kIo, std::string("GLSL compile failed: ") + log);
  }
  return s;
}

}  // namespace

Result<Program> linkProgram(const char* vs, const char* fs) {
  auto v = compile(GL_VERTEX_SHADER, vs);
  if (!v) return tl::unexpected(v.error());
  auto f = compile(GL_FRAGMENT_SHADER, fs);
  if (!f) return tl::unexpected(f.error());
  Program p(glCreateProgram());
  glAttachShader(p.get(), v->get());
  glAttachShader(p.get(), f->get());
  glLinkProgram(p.get());
  GLint ok = 0;
  glGetProgramiv(p.get(), GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetProgramInfoLog(p.get(), sizeof(log), nullptr, log);
    return fail(ErrorCode::kIo, std::string("GLSL link failed: ") + log);
  }
  return p;
}

namespace {

Result<SampleProgram> sampleProgram(const char* vs) {
  auto p = linkProgram(vs, kSampleFs);
  if (!p) return tl::unexpected(p.error());
  SampleProgram s;
  s.clip = glGetUniformLocation(p->get(), "uClip");
  s.tex = glGetUniformLocation(p->get(), "uTex");
  s.source = glGetUniformLocation(p->get(), "uSource");
  s.program = std::move(*p);
  return s;
}

}  // namespace

Result<Programs> buildPrograms() {
  Programs out;
  auto s2 = sampleProgram(kSample2dVs);
  if (!s2) return tl::unexpected(s2.error());
  out.sample_2d = std::move(*s2);
  auto sm = sampleProgram(kSampleMeshVs);
  if (!sm) return tl::unexpected(sm.error());
  out.sample_mesh = std::move(*sm);
  auto c = linkProgram(kColorVs, kColorFs);
  if (!c) return tl::unexpected(c.error());
  out.color.clip = glGetUniformLocation(c->get(), "uClip");
  out.color.program = std::move(*c);
  auto f = linkProgram(kFinalVs, kFinalFs);
  if (!f) return tl::unexpected(f.error());
  const GLuint id = f->get();
  out.final_stage.clip = glGetUniformLocation(id, "uClip");
  out.final_stage.frame = glGetUniformLocation(id, "uFrame");
  out.final_stage.mask = glGetUniformLocation(id, "uMask");
  out.final_stage.weight_lut = glGetUniformLocation(id, "uWeightLut");
  out.final_stage.output_lut = glGetUniformLocation(id, "uOutputLut");
  out.final_stage.has_mask = glGetUniformLocation(id, "uHasMask");
  out.final_stage.program = std::move(*f);
  return out;
}

}  // namespace procam::output::gl
