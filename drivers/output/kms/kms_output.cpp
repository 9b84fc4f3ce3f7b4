#include "kms/kms_output.hpp"

#include <poll.h>
#include <xf86drm.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>
#include <utility>

#include "core/monotonic_clock.hpp"

namespace procam::output::kms {
namespace {

struct FbData {
  int fd;
  uint32_t fb;
};

void destroyFb(gbm_bo*, void* data) {
  auto* d = static_cast<FbData*>(data);
  if (d->fb) drmModeRmFB(d->fd, d->fb);
  delete d;
}

Error drmError(const std::string& what) {
  return Error{ErrorCode::kIo, what + ": " + std::strerror(errno)};
}

}  // namespace

Result<std::unique_ptr<KmsOutput>> KmsOutput::create(const KmsConfig& config) {
  auto dev = DrmDevice::open(config.device);
  if (!dev) return tl::unexpected(dev.error());
  std::unique_ptr<KmsOutput> out(new KmsOutput(std::move(*dev)));
  out->flip_timeout_ms_ = config.flip_timeout_ms;
  auto connectors = out->dev_.connectors();
  if (!connectors) return tl::unexpected(connectors.error());
  auto choice = chooseOutput(*connectors, config.request);
  if (!choice) return tl::unexpected(choice.error());
  const Connector& c = (*connectors)[choice->connector];
  out->connector_ = c.id;
  out->connector_name_ = c.name;
  out->crtc_ = choice->crtc;
  out->mode_ = out->dev_.rawMode(choice->connector, choice->mode);
  out->plane_ = out->dev_.primaryPlane(out->crtc_);
  PropertyTable present;
  present.connector = out->dev_.propertyNames(out->connector_, DRM_MODE_OBJECT_CONNECTOR);
  present.crtc = out->dev_.propertyNames(out->crtc_, DRM_MODE_OBJECT_CRTC);
  if (out->plane_) present.plane = out->dev_.propertyNames(out->plane_, DRM_MODE_OBJECT_PLANE);
  out->atomic_ = chooseModesetApi(out->dev_.atomic() && out->plane_ != 0, present).atomic;
  out->saved_crtc_ = drmModeGetCrtc(out->dev_.fd(), out->crtc_);

  out->gbm_ = gbm_create_device(out->dev_.fd());
  if (!out->gbm_) return tl::unexpected(drmError("gbm_create_device"));
  out->surface_ =
      gbm_surface_create(out->gbm_, out->mode_.hdisplay, out->mode_.vdisplay, GBM_FORMAT_XRGB8888,
                         GBM_BO_USE_SCANOUT | GBM_BO_USE_RENDERING);
  if (!out->surface_) return tl::unexpected(drmError("gbm_surface_create"));
  out->thread_ = std::make_unique<egl::GlThread>();
  auto made = out->thread_->run([&]() -> Result<void> {
    auto ctx = egl::EglContext::forGbm(out->gbm_, out->surface_, GBM_FORMAT_XRGB8888);
    if (!ctx) return tl::unexpected(ctx.error());
    out->context_ = std::move(*ctx);
    if (auto ok = out->context_->makeCurrent(); !ok) return ok;
    // Rendered offscreen and blitted to the scan-out buffer, so that the frame shown can
    // be read back (status, snapshots) after the swap made the window's buffer undefined.
    auto r = gl::GlRenderer::create(gl::GlTarget{true, 0});
    if (!r) return tl::unexpected(r.error());
    out->renderer_ = std::move(*r);
    return {};
  });
  if (!made) return tl::unexpected(made.error());
  return out;
}

KmsOutput::~KmsOutput() {
  if (flip_pending_) (void)waitForFlip();
  // GL objects, surface and context go on the thread where the context is current,
  // before GBM and the DRM device below.
  if (thread_) {
    thread_->run([this] {
      renderer_.reset();
      context_.reset();
    });
  }
  if (saved_crtc_) {
    // Give the display back as it was found.
    drmModeSetCrtc(dev_.fd(), saved_crtc_->crtc_id, saved_crtc_->buffer_id, saved_crtc_->x,
                   saved_crtc_->y, &connector_, 1, &saved_crtc_->mode);
    drmModeFreeCrtc(saved_crtc_);
  }
  if (front_ && surface_) gbm_surface_release_buffer(surface_, front_);
  if (surface_) gbm_surface_destroy(surface_);
  if (gbm_) gbm_device_destroy(gbm_);
  if (mode_blob_) drmModeDestroyPropertyBlob(dev_.fd(), mode_blob_);
}

Result<void> KmsOutput::configure(const render::RenderSetup& setup) {
  if (setup.output_size != size()) {
    return fail(ErrorCode::kInvalidInput, "kms output: setup size differs from the display mode");
  }
  return thread_->run([&] { return renderer_->configure(setup); });
}

Result<bool> KmsOutput::show(const render::Content& content) {
  return thread_->run([&]() -> Result<bool> {
    auto rendered = renderer_->render(content);
    if (!rendered || !*rendered) return rendered;
    if (auto ok = renderer_->blitTo(0); !ok) return tl::unexpected(ok.error());
    if (auto ok = present(); !ok) return tl::unexpected(ok.error());
    shown_ = true;
    return true;
  });
}

Result<void> KmsOutput::readFrame(cv::Mat& rgba) {
  if (!shown_) return fail(ErrorCode::kInvalidInput, "kms output: no frame yet");
  return thread_->run([&] { return renderer_->readFrame(rgba); });
}

void KmsOutput::redraw() {
  thread_->run([this] { renderer_->redraw(); });
}

Result<uint32_t> KmsOutput::framebufferFor(gbm_bo* bo) {
  if (auto* d = static_cast<FbData*>(gbm_bo_get_user_data(bo))) return d->fb;
  uint32_t handles[4] = {gbm_bo_get_handle(bo).u32, 0, 0, 0};
  uint32_t strides[4] = {gbm_bo_get_stride(bo), 0, 0, 0};
  uint32_t offsets[4] = {0, 0, 0, 0};
  uint32_t fb = 0;
  if (drmModeAddFB2(dev_.fd(), gbm_bo_get_width(bo), gbm_bo_get_height(bo), gbm_bo_get_format(bo),
                    handles, strides, offsets, &fb, 0) != 0) {
    return tl::unexpected(drmError("drmModeAddFB2"));
  }
  gbm_bo_set_user_data(bo, new FbData{dev_.fd(), fb}, destroyFb);
  return fb;
}

Result<void> KmsOutput::commit(uint32_t fb, bool modeset) {
  const int fd = dev_.fd();
  if (!atomic_) {
    if (modeset) {
      if (drmModeSetCrtc(fd, crtc_, fb, 0, 0, &connector_, 1, &mode_) != 0) {
        return tl::unexpected(drmError("drmModeSetCrtc on " + connector_name_));
      }
      return {};
    }
    if (drmModePageFlip(fd, crtc_, fb, DRM_MODE_PAGE_FLIP_EVENT, this) != 0) {
      return tl::unexpected(drmError("drmModePageFlip"));
    }
    flip_pending_ = true;
    return {};
  }
  drmModeAtomicReq* req = drmModeAtomicAlloc();
  if (!req) return fail(ErrorCode::kIo, "drmModeAtomicAlloc failed");
  auto add = [&](uint32_t obj, uint32_t type, const char* name, uint64_t value) {
    const uint32_t prop = dev_.propertyId(obj, type, name);
    return prop != 0 && drmModeAtomicAddProperty(req, obj, prop, value) >= 0;
  };
  bool ok = true;
  if (modeset) {
    if (!mode_blob_ && drmModeCreatePropertyBlob(fd, &mode_, sizeof(mode_), &mode_blob_) != 0) {
      drmModeAtomicFree(req);
      return tl::unexpected(drmError("drmModeCreatePropertyBlob"));
    }
    ok = ok && add(connector_, DRM_MODE_OBJECT_CONNECTOR, "CRTC_ID", crtc_);
    ok = ok && add(crtc_, DRM_MODE_OBJECT_CRTC, "MODE_ID", mode_blob_);
    ok = ok && add(crtc_, DRM_MODE_OBJECT_CRTC, "ACTIVE", 1);
    const uint64_t w = mode_.hdisplay, h = mode_.vdisplay;
    ok = ok && add(plane_, DRM_MODE_OBJECT_PLANE, "CRTC_ID", crtc_);
    ok = ok && add(plane_, DRM_MODE_OBJECT_PLANE, "SRC_X", 0) &&
         add(plane_, DRM_MODE_OBJECT_PLANE, "SRC_Y", 0) &&
         add(plane_, DRM_MODE_OBJECT_PLANE, "SRC_W", w << 16) &&
         add(plane_, DRM_MODE_OBJECT_PLANE, "SRC_H", h << 16) &&
         add(plane_, DRM_MODE_OBJECT_PLANE, "CRTC_X", 0) &&
         add(plane_, DRM_MODE_OBJECT_PLANE, "CRTC_Y", 0) &&
         add(plane_, DRM_MODE_OBJECT_PLANE, "CRTC_W", w) &&
         add(plane_, DRM_MODE_OBJECT_PLANE, "CRTC_H", h);
  }
  ok = ok && add(plane_, DRM_MODE_OBJECT_PLANE, "FB_ID", fb);
  if (!ok) {
    drmModeAtomicFree(req);
    return fail(ErrorCode::kIo, "atomic request: a required KMS property is missing");
  }
  const uint32_t flags =
      modeset ? DRM_MODE_ATOMIC_ALLOW_MODESET : DRM_MODE_ATOMIC_NONBLOCK | DRM_MODE_PAGE_FLIP_EVENT;
  const int rc = drmModeAtomicCommit(fd, req, flags, this);
  drmModeAtomicFree(req);
  if (rc != 0) return tl::unexpected(drmError(modeset ? "atomic modeset" : "atomic page flip"));
  flip_pending_ = !modeset;
  return {};
}

void KmsOutput::onFlip(int, unsigned int sequence, unsigned int sec, unsigned int usec,
                       unsigned int, void* self) {
  auto* out = static_cast<KmsOutput*>(self);
  out->flip_pending_ = false;
  out->stats_.flip(sequence, sec + usec * 1e-6);
  out->last_flip_ns_ = uint64_t{sec} * 1'000'000'000u + uint64_t{usec} * 1000u;
}

uint64_t KmsOutput::periodNs() const {
  const double hz = refreshHz(mode_.clock, mode_.htotal, mode_.vtotal,
                              (mode_.flags & DRM_MODE_FLAG_INTERLACE) != 0,
                              (mode_.flags & DRM_MODE_FLAG_DBLSCAN) != 0);
  return hz > 0 ? static_cast<uint64_t>(std::llround(1e9 / hz)) : 0;
}

std::optional<ProjectorOutput::Timing> KmsOutput::vblankTiming() const {
  const uint64_t period = periodNs();
  if (last_flip_ns_ == 0 || ready_ns_ == 0 || period == 0) return std::nullopt;
  return Timing{ready_ns_, last_flip_ns_, period};
}

// Asked for a later vblank than the next: wait until the period before it, so that the
// flip committed then lands on it.
void KmsOutput::waitForVblankAsked() {
  const uint64_t period = periodNs();
  const uint64_t asked = std::exchange(not_before_ns_, 0);
  if (asked == 0 || last_flip_ns_ == 0 || period == 0) return;
  const uint64_t now = monotonicNowNs();
  const uint64_t from = std::max(asked, now);
  const uint64_t k = (from - std::min(from, last_flip_ns_) + period - 1) / period;
  const uint64_t target = last_flip_ns_ + k * period;
  // Half a millisecond into the period before the target vblank.
  const uint64_t commit_at = target - period + 500'000;
  if (commit_at > now) {
    std::this_thread::sleep_for(std::chrono::nanoseconds(commit_at - now));
  }
}

Result<void> KmsOutput::waitForFlip() {
  drmEventContext ev{};
  ev.version = 3;
  ev.page_flip_handler2 = &KmsOutput::onFlip;
  while (flip_pending_) {
    pollfd p{dev_.fd(), POLLIN, 0};
    const int n = poll(&p, 1, flip_timeout_ms_);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return fail(ErrorCode::kIo, "page flip on " + connector_name_ + " timed out");
    if (drmHandleEvent(dev_.fd(), &ev) != 0) return tl::unexpected(drmError("drmHandleEvent"));
  }
  return {};
}

Result<void> KmsOutput::present() {
  if (auto ok = context_->swapBuffers(); !ok) return ok;
  gbm_bo* bo = gbm_surface_lock_front_buffer(surface_);
  if (!bo) return fail(ErrorCode::kIo, "gbm_surface_lock_front_buffer: no buffer");
  auto fb = framebufferFor(bo);
  if (!fb) {
    gbm_surface_release_buffer(surface_, bo);
    return tl::unexpected(fb.error());
  }
  ready_ns_ = monotonicNowNs();
  if (mode_set_) waitForVblankAsked();
  if (auto ok = commit(*fb, !mode_set_); !ok) {
    gbm_surface_release_buffer(surface_, bo);
    return ok;
  }
  mode_set_ = true;
  if (auto ok = waitForFlip(); !ok) return ok;  // paced by vblank
  if (front_) gbm_surface_release_buffer(surface_, front_);
  front_ = bo;
  return {};
}

}  // namespace procam::output::kms
