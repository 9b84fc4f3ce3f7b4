#pragma once
// Output without a display: GLES 3 on the surfaceless EGL platform, frames rendered
// into a framebuffer object on the output's own GL thread (egl/gl_thread.hpp). With a sink (the
// virtual rig) every frame is read back to memory and handed to it; without one a frame is read
// back only on request (readFrame, lastFrame, writePng), so a frame costs the GPU's time alone.
#include <memory>
#include <string>

#include "egl/egl_context.hpp"
#include "egl/gl_thread.hpp"
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
  Result<void> readFrame(cv::Mat& rgba) override;
  void redraw() override;

  void setSink(FrameSink sink) { sink_ = std::move(sink); }
  // RGBA, empty before the first frame (read back when needed).
  const cv::Mat& lastFrame();
  uint64_t frameCount() const { return frames_; }
  // Writes the last frame as an RGBA PNG; kInvalidInput before the first frame, kIo on failure.
  Result<void> writePng(const std::string& path);
  std::string glRenderer() const;

 private:
  HeadlessOutput() = default;
  // Every GL call runs on thread_, where the context is current for its whole life; the
  // destructor releases renderer and context there before the thread ends.
  std::unique_ptr<egl::GlThread> thread_;
  std::unique_ptr<egl::EglContext> context_;
  std::unique_ptr<gl::GlRenderer> renderer_;
  cv::Size size_;
  cv::Mat frame_;
  uint64_t frames_ = 0;
  uint64_t read_ = 0;  // the frame number frame_ holds
  FrameSink sink_;
};

}  // namespace procam::output
