#pragma once
// The mock output: shows frames in the virtual rig (drivers/sim). Frames are drawn by
// the CPU reference renderer and put on the rig's framebuffer board under the
// projector's name, where the sim renderer lights the world with them.
#include <memory>
#include <string>

#include "output.hpp"
#include "render/cpu_renderer.hpp"
#include "sim/renderer.hpp"

namespace procam::output {

class MockOutput final : public ProjectorOutput {
 public:
  // `board` is the rig's projector-name -> framebuffer map; it must outlive the output.
  // kNotFound when the scene has no such projector.
  static Result<std::unique_ptr<MockOutput>> create(const sim::Scene& scene,
                                                    const std::string& projector,
                                                    sim::Framebuffers* board);

  const char* name() const override { return "mock"; }
  cv::Size size() const override { return size_; }
  Result<void> configure(const render::RenderSetup& setup) override;
  Result<bool> show(const render::Content& content) override;
  Result<void> readFrame(cv::Mat& rgba) override;
  void redraw() override { renderer_.redraw(); }

  const cv::Mat& lastFrame() const { return frame_; }  // RGBA

 private:
  MockOutput() = default;
  std::string projector_;
  sim::Framebuffers* board_ = nullptr;
  cv::Size size_;
  render::CpuRenderer renderer_;
  cv::Mat frame_;
};

}  // namespace procam::output
