#pragma once
// A projector output: renders content through its renderer and presents the frame
// (scan-out on a real display, memory for the headless output, the virtual rig for the
// mock). Plain C++ interface; every implementation owns its handles (RAII).
// Threads: an output is driven by one thread at a time, any thread, and may be destroyed on
// any thread. A GLES output runs its GL calls on a thread of its own (egl/gl_thread.hpp).
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <optional>

#include "core/error.hpp"
#include "render/render_setup.hpp"

namespace procam::output {

// Receives every newly presented frame: CV_8UC4 RGBA, row 0 at the top.
using FrameSink = std::function<void(const cv::Mat& rgba, uint64_t frame_number)>;

class ProjectorOutput {
 public:
  virtual ~ProjectorOutput() = default;
  virtual const char* name() const = 0;
  virtual cv::Size size() const = 0;
  virtual Result<void> configure(const render::RenderSetup& setup) = 0;
  // Renders and presents the content; false (nothing done) when neither content nor
  // geometry changed since the last frame.
  virtual Result<bool> show(const render::Content& content) = 0;
  // The frame last presented (CV_8UC4 RGBA, row 0 at the top); may read it back from the
  // GPU. kInvalidInput before the first frame.
  virtual Result<void> readFrame(cv::Mat& rgba) = 0;
  // The next show() draws even when nothing changed (something else was shown meanwhile).
  virtual void redraw() = 0;
  // Outputs that present at their display's vblank (a page flip; show() returns once the
  // frame is on screen). presentAt: the next show() presents at the first vblank at or
  // after not_before_ns (CLOCK_MONOTONIC; 0: the first after its drawing ends).
  // vblankTiming: the last frame's drawing end and vblank (CLOCK_MONOTONIC ns) and the
  // refresh period; nullopt for outputs that show a frame when its drawing ends (the
  // plugin holds their frames itself) and before the first vblank.
  struct Timing {
    uint64_t ready_ns = 0, shown_ns = 0, period_ns = 0;
  };
  virtual void presentAt(uint64_t /*not_before_ns*/) {}
  virtual std::optional<Timing> vblankTiming() const { return std::nullopt; }
};

}  // namespace procam::output
