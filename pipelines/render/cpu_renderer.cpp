#include "render/cpu_renderer.hpp"

namespace procam::render {

Result<WarpMap> mainPathMap(const RenderSetup& setup) {
  // The map for the main pass is sized to the rendered image: the output frame.
  switch (setup.path) {
    case RenderPath::kHomography:
      return homographyMap(setup.homography, setup.output_size);
    case RenderPath::kTwoPassMesh:
      return projectiveTextureMap(setup.surface, setup.projector, setup.viewer, setup.output_size);
    case RenderPath::kLookupWarp:
      return gridMap(setup.lookup, setup.output_size);
    case RenderPath::kPlanar3d:
    case RenderPath::kShaderLamps:
      break;
  }
  return fail(ErrorCode::kInvalidInput, "cpu renderer: the planar 3D path draws triangles, no map");
}

Result<void> CpuRenderer::configure(const RenderSetup& setup) {
  if (auto ok = validateSetup(setup); !ok) return ok;
  const bool is3d = setup.path == RenderPath::kPlanar3d;  // triangles, drawn per frame
  auto main = is3d ? Result<WarpMap>(WarpMap{}) : mainPathMap(setup);
  if (!main) return tl::unexpected(main.error());
  auto packed = is3d ? PackedMap{} : packMap(*main, setup.content_size);
  if (!packed) return tl::unexpected(packed.error());
  PackedMap post;
  if (setup.post_warp) {
    auto grid = gridMap(*setup.post_warp, setup.output_size);
    if (!grid) return tl::unexpected(grid.error());
    auto p = packMap(*grid, setup.output_size);
    if (!p) return tl::unexpected(p.error());
    post = std::move(*p);
  }
  setup_ = setup;
  map_ = std::move(*main);
  packed_ = std::move(*packed);
  post_ = std::move(post);
  frame_ = cv::Mat(setup.output_size, CV_8UC4, cv::Scalar::all(0));
  gate_.geometryChanged();
  configured_ = true;
  return {};
}

Result<bool> CpuRenderer::render(const Content& content) {
  if (!configured_) return fail(ErrorCode::kInvalidInput, "cpu renderer: not configured");
  const bool is3d = setup_.path == RenderPath::kPlanar3d;
  if (is3d && !content.mesh) return fail(ErrorCode::kInvalidInput, "cpu renderer: no 3D mesh");
  if (!is3d && (!content.image || content.image->type() != CV_8UC4 ||
                content.image->size() != setup_.content_size)) {
    return fail(ErrorCode::kInvalidInput, "cpu renderer: content must be CV_8UC4 of content_size");
  }
  if (!gate_.needsRender(content.version)) return false;
  cv::Mat& main_out = setup_.post_warp ? stage_ : frame_;
  if (is3d) {
    auto ok = rasterizeColoredMesh(*content.mesh, setup_.planar3d, setup_.output_size, main_out,
                                   depth_, content.stop);
    // A stopped drawing leaves a partial frame and the gate unchanged (it records only a
    // finished frame): the next render draws in full.
    if (!ok) return tl::unexpected(ok.error());
    return finish(content.version);
  }
  if (static_cast<int>(content.image->step) != packed_.source_step) {
    auto repacked = packMap(map_, setup_.content_size, static_cast<int>(content.image->step));
    if (!repacked) return tl::unexpected(repacked.error());
    packed_ = std::move(*repacked);
  }
  if (auto ok = remapRgba(*content.image, packed_, main_out, kernel_); !ok) {
    return tl::unexpected(ok.error());
  }
  return finish(content.version);
}

// The stages after the main path: post-render warp, then the final stage.
Result<bool> CpuRenderer::finish(uint64_t version) {
  if (setup_.post_warp) {
    if (auto ok = remapRgba(stage_, post_, frame_, kernel_); !ok) return tl::unexpected(ok.error());
  }
  if (auto ok = applyFinalStage(setup_.final_stage, frame_); !ok) {
    return tl::unexpected(ok.error());
  }
  gate_.rendered(version);
  return true;
}

Result<void> CpuRenderer::readFrame(cv::Mat& out) {
  if (!configured_) return fail(ErrorCode::kInvalidInput, "cpu renderer: not configured");
  frame_.copyTo(out);
  return {};
}

}  // namespace procam::render
