#include "egl/egl_context.hpp"

#include <EGL/eglext.h>
#include <GLES3/gl3.h>

#include <cstring>
#include <map>
#include <mutex>
#include <vector>

#include "egl/driver_pin.hpp"

namespace procam::output::egl {
namespace {

bool hasExtension(const char* list, const char* name) {
  if (!list) return false;
  const size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n) {
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  }
  return false;
}

// eglGetPlatformDisplayEXT returns one handle per native display and eglTerminate ends
// it for every user in the process: count users so that the last one terminates.
std::mutex& displayMutex() {
  static std::mutex m;
  return m;
}
std::map<EGLDisplay, int>& displayUsers() {
  static std::map<EGLDisplay, int> users;
  return users;
}

void retainDisplay(EGLDisplay d) {
  std::lock_guard<std::mutex> lock(displayMutex());
  ++displayUsers()[d];
}

void releaseDisplay(EGLDisplay d) {
  std::lock_guard<std::mutex> lock(displayMutex());
  auto it = displayUsers().find(d);
  if (it == displayUsers().end()) return;
  if (--it->second == 0) {
    displayUsers().erase(it);
    eglTerminate(d);
  }
}

Error eglFailure(const char* what) {
  return Error{ErrorCode::kIo, std::string(what) + " failed: " + eglErrorName(eglGetError())};
}

// Opens the display of a platform, initialises it and creates a GLES 3 context on a
// config matching `surface_type` (and `visual` when non-zero).
Result<void> open(EGLenum platform, void* native, EGLint surface_type, EGLint visual,
                  EGLDisplay& display, EGLContext& context, EGLConfig& config_out) {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!hasExtension(client, "EGL_EXT_platform_base")) {
    return fail(ErrorCode::kNotFound, "EGL: EGL_EXT_platform_base not supported");
  }
  auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!getPlatformDisplay) return fail(ErrorCode::kNotFound, "EGL: no eglGetPlatformDisplayEXT");
  display = getPlatformDisplay(platform, native, nullptr);
  if (display == EGL_NO_DISPLAY) return tl::unexpected(eglFailure("eglGetPlatformDisplayEXT"));
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) {
    Error e = eglFailure("eglInitialize");
    display = EGL_NO_DISPLAY;
    return tl::unexpected(e);
  }
  retainDisplay(display);
  pinLoadedGlDrivers();
  if (!eglBindAPI(EGL_OPENGL_ES_API)) return tl::unexpected(eglFailure("eglBindAPI"));
  const EGLint attrs[] = {EGL_SURFACE_TYPE,
                          surface_type,
                          EGL_RENDERABLE_TYPE,
                          EGL_OPENGL_ES3_BIT,
                          EGL_RED_SIZE,
                          8,
                          EGL_GREEN_SIZE,
                          8,
                          EGL_BLUE_SIZE,
                          8,
                          EGL_NONE};
  EGLint count = 0;
  if (!eglChooseConfig(display, attrs, nullptr, 0, &count) || count == 0) {
    return fail(ErrorCode::kNotFound, "EGL: no GLES 3 config");
  }
  std::vector<EGLConfig> configs(static_cast<size_t>(count));
  eglChooseConfig(display, attrs, configs.data(), count, &count);
  EGLConfig chosen = configs[0];
  if (visual != 0) {
    chosen = nullptr;
    for (EGLConfig c : configs) {
      EGLint id = 0;
      if (eglGetConfigAttrib(display, c, EGL_NATIVE_VISUAL_ID, &id) && id == visual) {
        chosen = c;
        break;
      }
    }
    if (!chosen) return fail(ErrorCode::kNotFound, "EGL: no config for the scan-out format");
  }
  const EGLint ctx_attrs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_NONE};
  context = eglCreateContext(display, chosen, EGL_NO_CONTEXT, ctx_attrs);
  if (context == EGL_NO_CONTEXT) return tl::unexpected(eglFailure("eglCreateContext"));
  config_out = chosen;
  return {};
}

}  // namespace

std::string eglErrorName(EGLint error) {
  switch (error) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE:
      return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP:
      return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW:
      return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE:
      return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST:
      return "EGL_CONTEXT_LOST";
    default:
      return "EGL error " + std::to_string(error);
  }
}

Result<std::unique_ptr<EglContext>> EglContext::surfaceless() {
  std::unique_ptr<EglContext> c(new EglContext());
  EGLConfig config = nullptr;
  if (auto ok = open(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, EGL_PBUFFER_BIT, 0,
                     c->display_, c->context_, config);
      !ok) {
    return tl::unexpected(ok.error());
  }
  if (!hasExtension(eglQueryString(c->display_, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context")) {
    return fail(ErrorCode::kNotFound, "EGL: EGL_KHR_surfaceless_context not supported");
  }
  if (auto ok = c->makeCurrent(); !ok) return tl::unexpected(ok.error());
  return c;
}

Result<std::unique_ptr<EglContext>> EglContext::forGbm(gbm_device* device, gbm_surface* surface,
                                                       uint32_t gbm_format) {
  std::unique_ptr<EglContext> c(new EglContext());
  EGLConfig config = nullptr;
  if (auto ok = open(EGL_PLATFORM_GBM_KHR, device, EGL_WINDOW_BIT, static_cast<EGLint>(gbm_format),
                     c->display_, c->context_, config);
      !ok) {
    return tl::unexpected(ok.error());
  }
  auto createSurface = reinterpret_cast<PFNEGLCREATEPLATFORMWINDOWSURFACEEXTPROC>(
      eglGetProcAddress("eglCreatePlatformWindowSurfaceEXT"));
  if (!createSurface) return fail(ErrorCode::kNotFound, "EGL: no platform window surfaces");
  c->surface_ = createSurface(c->display_, config, surface, nullptr);
  if (c->surface_ == EGL_NO_SURFACE) {
    return tl::unexpected(eglFailure("eglCreatePlatformWindowSurfaceEXT"));
  }
  if (auto ok = c->makeCurrent(); !ok) return tl::unexpected(ok.error());
  return c;
}

EglContext::~EglContext() {
  if (display_ == EGL_NO_DISPLAY) return;
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (surface_ != EGL_NO_SURFACE) eglDestroySurface(display_, surface_);
  if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
  releaseDisplay(display_);
}

Result<void> EglContext::makeCurrent() {
  if (eglGetCurrentContext() == context_) return {};
  if (!eglMakeCurrent(display_, surface_, surface_, context_)) {
    return tl::unexpected(eglFailure("eglMakeCurrent"));
  }
  return {};
}

Result<void> EglContext::swapBuffers() {
  if (surface_ == EGL_NO_SURFACE) return fail(ErrorCode::kInvalidInput, "EGL: no window surface");
  if (!eglSwapBuffers(display_, surface_)) return tl::unexpected(eglFailure("eglSwapBuffers"));
  return {};
}

std::string EglContext::renderer() const {
  const auto* s = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  return s ? s : "";
}

}  // namespace procam::output::egl
