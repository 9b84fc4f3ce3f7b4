#pragma once
// RAII owners for GLES 3 object names. Every object is deleted on the thread and with
// the context that created it: owners must die before their context is destroyed.
#include <GLES3/gl3.h>

#include <utility>

namespace procam::output::gl {

template <void (*Delete)(GLuint)>
class GlName {
 public:
  GlName() = default;
  explicit GlName(GLuint id) : id_(id) {}
  GlName(GlName&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  GlName& operator=(GlName&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, 0);
    }
    return *this;
  }
  GlName(const GlName&) = delete;
  GlName& operator=(const GlName&) = delete;
  ~GlName() { reset(); }
  GLuint get() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  void reset() {
    if (id_ != 0) Delete(id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
};

namespace detail {
inline void deleteTexture(GLuint id) {
  glDeleteTextures(1, &id);
}
inline void deleteFramebuffer(GLuint id) {
  glDeleteFramebuffers(1, &id);
}
inline void deleteRenderbuffer(GLuint id) {
  glDeleteRenderbuffers(1, &id);
}
inline void deleteBuffer(GLuint id) {
  glDeleteBuffers(1, &id);
}
inline void deleteVertexArray(GLuint id) {
  glDeleteVertexArrays(1, &id);
}
inline void deleteProgram(GLuint id) {
  glDeleteProgram(id);
}
inline void deleteShader(GLuint id) {
  glDeleteShader(id);
}
}  // namespace detail

using Texture = GlName<detail::deleteTexture>;
using Framebuffer = GlName<detail::deleteFramebuffer>;
using Renderbuffer = GlName<detail::deleteRenderbuffer>;
using Buffer = GlName<detail::deleteBuffer>;
using VertexArray = GlName<detail::deleteVertexArray>;
using Program = GlName<detail::deleteProgram>;
using Shader = GlName<detail::deleteShader>;

inline Texture makeTexture() {
  GLuint id = 0;
  glGenTextures(1, &id);
  return Texture(id);
}
inline Framebuffer makeFramebuffer() {
  GLuint id = 0;
  glGenFramebuffers(1, &id);
  return Framebuffer(id);
}
inline Renderbuffer makeRenderbuffer() {
  GLuint id = 0;
  glGenRenderbuffers(1, &id);
  return Renderbuffer(id);
}
inline Buffer makeBuffer() {
  GLuint id = 0;
  glGenBuffers(1, &id);
  return Buffer(id);
}
inline VertexArray makeVertexArray() {
  GLuint id = 0;
  glGenVertexArrays(1, &id);
  return VertexArray(id);
}

}  // namespace procam::output::gl
