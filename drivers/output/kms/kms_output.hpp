#pragma once
// Projector output on a real display: DRM/KMS + GBM + EGL. Connector and mode from
// configuration, atomic modesetting with a legacy fallback, one page flip per new frame
// on vblank, frame-time and missed-vblank statistics. The frame is drawn by the GLES 3
// renderer straight into the scan-out surface.
#include <gbm.h>

#include <memory>
#include <string>

#include "egl/egl_context.hpp"
#include "egl/gl_thread.hpp"
#include "gl/gl_renderer.hpp"
#include "kms/kms_device.hpp"
#include "kms/kms_select.hpp"
#include "output.hpp"

namespace procam::output::kms {

struct KmsConfig {
  std::string device;     // "/dev/dri/cardN" or "" for the first display-capable card
  OutputRequest request;  // connector name and mode
  int flip_timeout_ms = 1000;
};

class KmsOutput final : public ProjectorOutput {
 public:
  // kNotFound "no DRM device ..." / kIo "not DRM master ..." and the other causes of
  // DrmDevice::open and chooseOutput, unchanged.
  static Result<std::unique_ptr<KmsOutput>> create(const KmsConfig& config);
  ~KmsOutput() override;

  const char* name() const override { return "kms"; }
  cv::Size size() const override { return {mode_.hdisplay, mode_.vdisplay}; }
  Result<void> configure(const render::RenderSetup& setup) override;
  Result<bool> show(const render::Content& content) override;
  Result<void> readFrame(cv::Mat& rgba) override;
  void redraw() override;
  // Flips are timed by the page-flip events (CLOCK_MONOTONIC, the kernel's default for
  // them): a frame is committed in the period before the vblank asked for.
  void presentAt(uint64_t not_before_ns) override { not_before_ns_ = not_before_ns; }
  std::optional<Timing> vblankTiming() const override;

  const FrameStats& stats() const { return stats_; }
  const std::string& connectorName() const { return connector_name_; }
  bool atomic() const { return atomic_; }

 private:
  explicit KmsOutput(DrmDevice dev) : dev_(std::move(dev)) {}
  Result<void> present();
  Result<uint32_t> framebufferFor(gbm_bo* bo);
  Result<void> commit(uint32_t fb, bool modeset);
  Result<void> waitForFlip();
  void waitForVblankAsked();
  uint64_t periodNs() const;  // of the mode; 0 when its totals are zero
  static void onFlip(int fd, unsigned int sequence, unsigned int sec, unsigned int usec,
                     unsigned int crtc, void* self);

  DrmDevice dev_;
  drmModeModeInfo mode_{};
  uint32_t connector_ = 0, crtc_ = 0, plane_ = 0, mode_blob_ = 0;
  std::string connector_name_;
  bool atomic_ = false;
  drmModeCrtc* saved_crtc_ = nullptr;
  gbm_device* gbm_ = nullptr;
  gbm_surface* surface_ = nullptr;
  // Every GL call (and the page flip after it) runs on thread_, where the context is
  // current for its whole life (egl/gl_thread.hpp).
  std::unique_ptr<egl::GlThread> thread_;
  std::unique_ptr<egl::EglContext> context_;
  bool shown_ = false;
  std::unique_ptr<gl::GlRenderer> renderer_;
  gbm_bo* front_ = nullptr;
  bool mode_set_ = false, flip_pending_ = false;
  int flip_timeout_ms_ = 1000;
  FrameStats stats_;
  uint64_t last_flip_ns_ = 0;   // the vblank of the latest page flip
  uint64_t ready_ns_ = 0;       // the latest frame's drawing ended
  uint64_t not_before_ns_ = 0;  // the next flip's earliest vblank (0: the next)
};

}  // namespace procam::output::kms
