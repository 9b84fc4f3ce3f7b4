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
  auto r = gl::GlRenderer::create(gl::GlTarget{true, 0});
  if (!r) return tl::unexpected(r.error());
  out->renderer_ = std::move(*r);
  out->size_ = size;
  return out;
}

HeadlessOutput::~HeadlessOutput() {
  // GL objects are deleted in the context that made them, which another output may have
  // replaced as the current one.
  if (context_ && renderer_) (void)context_->makeCurrent();
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
  if (auto ok = renderer_->readFrame(frame_); !ok) return tl::unexpected(ok.error());
  ++frames_;
  if (sink_) sink_(frame_, frames_);
  return true;
}

Result<void> HeadlessOutput::writePng(const std::string& path) const {
  if (frame_.empty()) return fail(ErrorCode::kInvalidInput, "headless output: no frame yet");
  cv::Mat bgra;
  cv::cvtColor(frame_, bgra, cv::COLOR_RGBA2BGRA);
  try {
    if (!cv::imwrite(path, bgra)) return fail(ErrorCode::kIo, "cannot write PNG " + path);
  } catch (const cv::Exception& e) {
    return fail(ErrorCode::kIo, "cannot write PNG " + path + ": " + e.what());
  }
  return {};
}

}  // namespace procam::output
