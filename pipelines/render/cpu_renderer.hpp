#pragma once
// The CPU reference renderer: every image path becomes a precomputed warp map applied
// with integer bilinear interpolation on all cores, the planar 3D path rasterizes its
// triangles (raster_triangles.hpp); the post-render warp (§4.1.3) is a
// second map applied to the rendered image, as the GL back-end does; the final stage
// comes last. It is the specification the GL back-end is tested against and the
// fallback output path.
#include "render/packed_map.hpp"
#include "render/raster_triangles.hpp"
#include "render/remap_rgba.hpp"
#include "render/renderer.hpp"

namespace procam::render {

class CpuRenderer final : public Renderer {
 public:
  const char* name() const override { return "cpu"; }
  Result<void> configure(const RenderSetup& setup) override;
  Result<bool> render(const Content& content) override;
  Result<void> readFrame(cv::Mat& out) override;
  void redraw() override { gate_.geometryChanged(); }
  // The current frame (CV_8UC4, output size), shared: valid until the next render.
  const cv::Mat& frame() const { return frame_; }

  const WarpMap& map() const { return map_; }  // the main-path map of the current setup
  void setKernel(RemapKernel kernel) { kernel_ = kernel; }

 private:
  RenderSetup setup_;
  WarpMap map_;
  PackedMap packed_;
  PackedMap post_;  // empty unless setup.post_warp
  cv::Mat stage_;   // main-path image when a post-render warp follows
  cv::Mat frame_;
  cv::Mat depth_;  // kPlanar3d depth buffer
  FrameGate gate_;
  RemapKernel kernel_ = RemapKernel::kBest;
  bool configured_ = false;

  Result<bool> finish(uint64_t version);
};

// The main-path map of a setup (before the post-render warp); kInvalidInput for kPlanar3d.
Result<WarpMap> mainPathMap(const RenderSetup& setup);

}  // namespace procam::render
