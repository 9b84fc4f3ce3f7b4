#include "render/render_setup.hpp"

namespace procam::render {
namespace {

bool validSize(cv::Size s) {
  return s.width > 0 && s.height > 0;
}

bool sameGrid(const WarpGrid& a, const WarpGrid& b) {
  return a.cols == b.cols && a.rows == b.rows && a.origin == b.origin && a.step == b.step &&
         a.source == b.source;
}

}  // namespace

bool sameSetup(const RenderSetup& a, const RenderSetup& b) {
  if (a.output_size != b.output_size || a.content_size != b.content_size || a.path != b.path ||
      a.homography != b.homography || a.projector != b.projector || a.viewer != b.viewer ||
      a.planar3d != b.planar3d || a.surface.vertices != b.surface.vertices ||
      a.surface.triangles != b.surface.triangles || !sameGrid(a.lookup, b.lookup) ||
      a.post_warp.has_value() != b.post_warp.has_value()) {
    return false;
  }
  if (a.post_warp && !sameGrid(*a.post_warp, *b.post_warp)) return false;
  return sameStage(a.final_stage, b.final_stage);
}

Result<void> validateSetup(const RenderSetup& s) {
  if (!validSize(s.output_size)) return fail(ErrorCode::kInvalidInput, "setup: empty output size");
  if (s.path != RenderPath::kPlanar3d && (s.content_size.width < 2 || s.content_size.height < 2)) {
    return fail(ErrorCode::kInvalidInput, "setup: content must be at least 2x2 pixels");
  }
  switch (s.path) {
    case RenderPath::kHomography:
      if (!s.homography.allFinite()) return fail(ErrorCode::kInvalidInput, "setup: non-finite H");
      break;
    case RenderPath::kTwoPassMesh:
      if (s.surface.triangles.empty() || !s.projector.allFinite() || !s.viewer.allFinite() ||
          s.projector.isZero() || s.viewer.isZero()) {
        return fail(ErrorCode::kInvalidInput,
                    "setup: two-pass path needs a surface mesh, projector and viewer matrices");
      }
      break;
    case RenderPath::kLookupWarp:
      if (s.lookup.cols < 2 || s.lookup.rows < 2) {
        return fail(ErrorCode::kInvalidInput, "setup: lookup warp needs a grid of >= 2x2 nodes");
      }
      break;
    case RenderPath::kPlanar3d:
      if (!s.planar3d.allFinite()) return fail(ErrorCode::kInvalidInput, "setup: non-finite A'P_T");
      break;
    case RenderPath::kShaderLamps:
      return fail(ErrorCode::kInvalidInput,
                  "setup: shader-lamps frames are computed per pixel and shown by the homography "
                  "path");
  }
  if (!s.final_stage.alpha.empty() &&
      (s.final_stage.alpha.type() != CV_8UC1 || s.final_stage.alpha.size() != s.output_size)) {
    return fail(ErrorCode::kInvalidInput, "setup: alpha mask must be CV_8UC1 of the output size");
  }
  return {};
}

}  // namespace procam::render
