#include "render/render_path.hpp"

namespace procam::render {

Result<PathChoice> choosePath(const SceneTraits& scene) {
  if (scene.projectors < 1) return fail(ErrorCode::kInvalidInput, "choosePath: no projector");
  PathChoice c;
  c.post_warp = scene.projectors > 1;
  c.blend = scene.projectors > 1;
  switch (scene.surface) {
    case SurfaceKind::kPlanar:
      // A plane never pays for two passes: image content (or an untracked viewer) is one
      // homography; 3D content for a tracked viewer folds the homography into A'4x4 P_T.
      // A static viewer is a tracked one who stands still: the same single pass.
      c.path = scene.viewer != ViewerKind::kUntracked && scene.content == ContentKind::kMesh3d
                   ? RenderPath::kPlanar3d
                   : RenderPath::kHomography;
      // Planar tiles are registered exactly by homography chains (§4.2.4): no grid warp.
      c.post_warp = false;
      return c;
    case SurfaceKind::kNonPlanar:
      c.path =
          scene.viewer == ViewerKind::kTracked ? RenderPath::kTwoPassMesh : RenderPath::kLookupWarp;
      // The measured lookup warp already maps to the exact illuminated pixels (§4.1.5).
      if (c.path == RenderPath::kLookupWarp) c.post_warp = false;
      return c;
    case SurfaceKind::kObject:
      // Rendered from each projector with its own radiance correction and weights
      // ([Raskar02] §5.2.5 feathering by reach and depth discontinuities): no post warp,
      // the weights are the blend. The look does not depend on the content kind.
      c.path = RenderPath::kShaderLamps;
      c.post_warp = false;
      return c;
  }
  return fail(ErrorCode::kInvalidInput, "choosePath: unknown surface kind");
}

const char* toString(RenderPath path) {
  switch (path) {
    case RenderPath::kHomography:
      return "homography";
    case RenderPath::kPlanar3d:
      return "planar-3d";
    case RenderPath::kTwoPassMesh:
      return "two-pass-mesh";
    case RenderPath::kLookupWarp:
      return "lookup-warp";
    case RenderPath::kShaderLamps:
      return "shader-lamps";
  }
  return "unknown";
}

}  // namespace procam::render
