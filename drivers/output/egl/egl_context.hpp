#pragma once
// RAII ownership of an EGL display connection and a GLES 3 context, current on the
// creating thread. Two ways in: Mesa's surfaceless platform (no display, no DRM device:
// rendering into framebuffer objects), and a GBM device with a window surface (KMS).
#include <EGL/egl.h>

#include <memory>
#include <string>

#include "core/error.hpp"

struct gbm_device;
struct gbm_surface;

namespace procam::output::egl {

class EglContext {
 public:
  // Surfaceless platform (EGL_PLATFORM_SURFACELESS_MESA); kNotFound when the EGL client
  // extensions or a GLES 3 config are missing.
  static Result<std::unique_ptr<EglContext>> surfaceless();
  // GBM platform with a window surface on `surface` whose buffers use `gbm_format`.
  static Result<std::unique_ptr<EglContext>> forGbm(gbm_device* device, gbm_surface* surface,
                                                    uint32_t gbm_format);
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  Result<void> makeCurrent();
  Result<void> swapBuffers();    // window surfaces only
  std::string renderer() const;  // GL_RENDERER string, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"

 private:
  EglContext() = default;
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  EGLSurface surface_ = EGL_NO_SURFACE;
};

// Human-readable name of an EGL error code.
std::string eglErrorName(EGLint error);

}  // namespace procam::output::egl
