#pragma once
// Output without a display: GLES 3 on Mesa's surfaceless EGL platform, frames rendered
// into a framebuffer object, read back to memory, handed to a sink (the virtual rig) and
// written as PNG on request.
#include <memory>
#include <string>

#include "egl/egl_context.hpp"
#include "gl/gl_renderer.hpp"
#include "output.hpp"

namespace procam::output {

class HeadlessOutput final : public ProjectorOutput {
 public:
  // kNotFound (with the EGL cause) when no surfaceless GLES 3 context can be created.
  static Result<std::unique_ptr<HeadlessOutput>> create(cv::Size size);
  ~HeadlessOutput() override;

  const char* name() const override { return "headless"; }
  cv::Size size() const override { return size_; }
  Result<void> configure(const render::RenderSetup& setup) override;
  Result<bool> show(const render::Content& content) override;

  void setSink(FrameSink sink) { sink_ = std::move(sink); }
  const cv::Mat& lastFrame() const { return frame_; }  // RGBA, empty before the first frame
  uint64_t frameCount() const { return frames_; }
  // Writes the last frame as an RGBA PNG; kInvalidInput before the first frame, kIo on failure.
  Result<void> writePng(const std::string& path) const;
  std::string glRenderer() const { return context_->renderer(); }

 private:
  HeadlessOutput() = default;
  // Declaration order = reverse destruction order: the renderer's GL objects go first.
  std::unique_ptr<egl::EglContext> context_;
  std::unique_ptr<gl::GlRenderer> renderer_;
  cv::Size size_;
  cv::Mat frame_;
  uint64_t frames_ = 0;
  FrameSink sink_;
};

}  // namespace procam::output
