#pragma once
// Choice of the cheapest rendering path a scene allows (ARCHITECTURE.md's table).
#include "core/error.hpp"

namespace procam::render {

enum class SurfaceKind { kPlanar, kNonPlanar, kObject };
enum class ViewerKind { kUntracked, kStatic, kTracked };
enum class ContentKind { kImage, kMesh3d };

struct SceneTraits {
  SurfaceKind surface = SurfaceKind::kPlanar;
  ViewerKind viewer = ViewerKind::kUntracked;
  ContentKind content = ContentKind::kImage;
  int projectors = 1;  // > 1 adds the post-render warp and blending stages
};

enum class RenderPath {
  kHomography,   // planar surface: one 3x3 pre-warp ([Raskar02] §3.2.5, §4.2.1, §4.2.4 chains)
  kPlanar3d,     // planar surface, tracked viewer, 3D content: A'4x4 P_T (§4.2.2-4.2.3)
  kTwoPassMesh,  // non-planar surface, tracked viewer: projective texture (§3.2.3, §4.1.1)
  kLookupWarp,   // non-planar surface, static viewer: measured lookup warp (§4.1.5)
  // Object surface: every projector pixel's radiance-corrected value is computed by
  // pipelines/shader_lamps (§5.2.4-5.2.5) and the frame is shown as it is. A RenderSetup
  // never carries this path: the frame goes out through kHomography with H = I.
  kShaderLamps,
};

struct PathChoice {
  RenderPath path = RenderPath::kHomography;
  bool post_warp = false;  // several projectors: post-rendering warp (§4.1.3)
  bool blend = false;      // several projectors: alpha mask + weight LUT (§4.1.2)
};

// kInvalidInput for projectors < 1.
Result<PathChoice> choosePath(const SceneTraits& scene);

const char* toString(RenderPath path);

}  // namespace procam::render
