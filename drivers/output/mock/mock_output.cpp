#include "mock/mock_output.hpp"

#include <opencv2/imgproc.hpp>

namespace procam::output {

Result<std::unique_ptr<MockOutput>> MockOutput::create(const sim::Scene& scene,
                                                       const std::string& projector,
                                                       sim::Framebuffers* board) {
  if (!board) return fail(ErrorCode::kInvalidInput, "mock output: no framebuffer board");
  for (const auto& p : scene.projectors()) {
    if (p.name != projector) continue;
    std::unique_ptr<MockOutput> out(new MockOutput());
    out->projector_ = projector;
    out->board_ = board;
    out->size_ = cv::Size(p.width, p.height);
    return out;
  }
  return fail(ErrorCode::kNotFound, "mock output: scene has no projector '" + projector + "'");
}

Result<void> MockOutput::configure(const render::RenderSetup& setup) {
  if (setup.output_size != size_) {
    return fail(ErrorCode::kInvalidInput, "mock output: setup size differs from the projector's");
  }
  return renderer_.configure(setup);
}

Result<bool> MockOutput::show(const render::Content& content) {
  auto rendered = renderer_.render(content);
  if (!rendered || !*rendered) return rendered;
  if (auto ok = renderer_.readFrame(frame_); !ok) return tl::unexpected(ok.error());
  cv::Mat bgra;
  cv::cvtColor(frame_, bgra, cv::COLOR_RGBA2BGRA);  // the rig's framebuffers are BGR(A)
  (*board_)[projector_] = bgra;
  return true;
}

Result<void> MockOutput::readFrame(cv::Mat& rgba) {
  if (frame_.empty()) return fail(ErrorCode::kInvalidInput, "mock output: no frame yet");
  rgba = frame_;
  return {};
}

}  // namespace procam::output
