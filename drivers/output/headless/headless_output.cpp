#include "headless/headless_output.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace procam::output {

Result<std::unique_ptr<HeadlessOutput>> HeadlessOutput::create(cv::Size size) {
  if (size.width <= 0 || size.height <= 0) {
    return fail(ErrorCode::kInvalidInput, "headless output: empty size");
  }
  std::unique_ptr<HeadlessOutput> out(new HeadlessOutput());
  auto ctx = egl::EglContext::surfaceless();
  if (!ctx) {
    return fail(ErrorCode::kNotFound,
                "headless output: no surfaceless EGL: " + ctx.error().message);
  }
  out->context_ = std::move(*ctx);
  egl::CurrentScope current(*out->context_);
  if (auto ok = current.bind(); !ok) return tl::unexpected(ok.error());
  auto r = gl::GlRenderer::create(gl::GlTarget{true, 0});
  if (!r) return tl::unexpected(r.error());
  out->renderer_ = std::move(*r);
  out->size_ = size;
  return out;
}

HeadlessOutput::~HeadlessOutput() {
  // GL objects are deleted in the context that made them, which another output may have
  // replaced as the current one.
  if (!context_) return;
  egl::CurrentScope current(*context_);
  if (renderer_) (void)current.bind();
  renderer_.reset();
}

Result<void> HeadlessOutput::configure(const render::RenderSetup& setup) {
  if (setup.output_size != size_) {
    return fail(ErrorCode::kInvalidInput, "headless output: setup size differs from output size");
  }
  if (auto ok = context_->makeCurrent(); !ok) return ok;
  return renderer_->configure(setup);
}

Result<bool> HeadlessOutput::show(const render::Content& content) {
  if (auto ok = context_->makeCurrent(); !ok) return tl::unexpected(ok.error());
  auto rendered = renderer_->render(content);
  if (!rendered || !*rendered) return rendered;
  ++frames_;
  if (sink_) {
    if (auto ok = renderer_->readFrame(frame_); !ok) return tl::unexpected(ok.error());
    read_ = frames_;
    sink_(frame_, frames_);
  }
  return true;
}

Result<void> HeadlessOutput::readFrame(cv::Mat& rgba) {
  if (frames_ == 0) return fail(ErrorCode::kInvalidInput, "headless output: no frame yet");
  if (read_ != frames_) {
    if (auto ok = context_->makeCurrent(); !ok) return ok;
    if (auto ok = renderer_->readFrame(frame_); !ok) return ok;
    read_ = frames_;
  }
  rgba = frame_;
  return {};
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
