#include "headless/headless_output.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace procam::output {

Result<std::unique_ptr<HeadlessOutput>> HeadlessOutput::create(cv::Size size) {
  if (size.width <= 0 || size.height <= 0) {
    return fail(ErrorCode::kInvalidInput, "headless output: empty size");
  }
  std::unique_ptr<HeadlessOutput> out(new HeadlessOutput());
  out->thread_ = std::make_unique<egl::GlThread>();
  auto made = out->thread_->run([&]() -> Result<void> {
    auto ctx = egl::EglContext::surfaceless();
    if (!ctx) {
      return fail(ErrorCode::kNotFound,
                  "headless output: no surfaceless EGL: " + ctx.error().message);
    }
    out->context_ = std::move(*ctx);
    if (auto ok = out->context_->makeCurrent(); !ok) return ok;
    auto r = gl::GlRenderer::create(gl::GlTarget{true, 0});
    if (!r) return tl::unexpected(r.error());
    out->renderer_ = std::move(*r);
    return {};
  });
  if (!made) return tl::unexpected(made.error());
  out->size_ = size;
  return out;
}

HeadlessOutput::~HeadlessOutput() {
  // GL objects and the context go on the thread where the context is current.
  if (thread_) {
    thread_->run([this] {
      renderer_.reset();
      context_.reset();
    });
  }
}

Result<void> HeadlessOutput::configure(const render::RenderSetup& setup) {
  if (setup.output_size != size_) {
    return fail(ErrorCode::kInvalidInput, "headless output: setup size differs from output size");
  }
  return thread_->run([&] { return renderer_->configure(setup); });
}

Result<bool> HeadlessOutput::show(const render::Content& content) {
  return thread_->run([&]() -> Result<bool> {
    auto rendered = renderer_->render(content);
    if (!rendered || !*rendered) return rendered;
    ++frames_;
    if (sink_) {
      if (auto ok = renderer_->readFrame(frame_); !ok) return tl::unexpected(ok.error());
      read_ = frames_;
      sink_(frame_, frames_);
    }
    return true;
  });
}

Result<void> HeadlessOutput::readFrame(cv::Mat& rgba) {
  if (frames_ == 0) return fail(ErrorCode::kInvalidInput, "headless output: no frame yet");
  if (read_ != frames_) {
    auto ok = thread_->run([&] { return renderer_->readFrame(frame_); });
    if (!ok) return ok;
    read_ = frames_;
  }
  rgba = frame_;
  return {};
}

void HeadlessOutput::redraw() {
  thread_->run([this] { renderer_->redraw(); });
}

std::string HeadlessOutput::glRenderer() const {
  return thread_->run([this] { return context_->renderer(); });
}

const cv::Mat& HeadlessOutput::lastFrame() {
  cv::Mat ignored;
  (void)readFrame(ignored);
  return frame_;
}

Result<void> HeadlessOutput::writePng(const std::string& path) {
  cv::Mat frame;
  if (auto ok = readFrame(frame); !ok) return ok;
  cv::Mat bgra;
  cv::cvtColor(frame, bgra, cv::COLOR_RGBA2BGRA);
  try {
    if (!cv::imwrite(path, bgra)) return fail(ErrorCode::kIo, "cannot write PNG " + path);
  } catch (const cv::Exception& e) {
    return fail(ErrorCode::kIo, "cannot write PNG " + path + ": " + e.what());
  }
  return {};
}

}  // namespace procam::output
