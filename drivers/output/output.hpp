#pragma once
// A projector output: renders content through its renderer and presents the frame
// (scan-out on a real display, memory for the headless output, the virtual rig for the
// mock). Plain C++ interface; every implementation owns its handles (RAII).
// Threads: an output is driven by one thread at a time, any thread, and may be destroyed on
// any thread. A GLES output runs its GL calls on a thread of its own (egl/gl_thread.hpp).
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>

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
};

}  // namespace procam::output
