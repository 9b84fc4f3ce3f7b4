#pragma once
// One interface for every rendering back-end (CPU reference here, GLES 3 in
// drivers/output/gl). A renderer owns the projector frame it draws into.
#include <opencv2/core.hpp>

#include "core/error.hpp"
#include "render/render_setup.hpp"

namespace procam::render {

class Renderer {
 public:
  virtual ~Renderer() = default;
  virtual const char* name() const = 0;
  // Validates the setup and precomputes everything that depends only on geometry.
  virtual Result<void> configure(const RenderSetup& setup) = 0;
  // Draws the content into the frame. Returns false, doing nothing, when neither the
  // geometry nor the content version changed since the last frame.
  virtual Result<bool> render(const Content& content) = 0;
  // Copies the current frame into `out` (CV_8UC4, output size, row 0 = top).
  virtual Result<void> readFrame(cv::Mat& out) = 0;
  // The next render() draws even when nothing changed (the frame was overwritten).
  virtual void redraw() = 0;
};

}  // namespace procam::render
