#pragma once
// One display from several projectors on a non-planar surface for a viewer at a sweet
// spot ([Raskar02] §4.1.5, §4.1.2): the content is the image the viewer should see, on
// the image plane of a pinhole at the eye that looks at the middle of the projectors'
// images with world +Z up. The content fills the largest upright rectangle of its aspect
// inside the union of the images as the eye sees them (coverage_raster.hpp: tested by
// casting the eye's rays onto the surface), every projector gets the lookup warp from its
// pixels to that content (render/viewer_view.hpp) and its eq. 4.3 weights
// (curved_feather.hpp), and the blend tables apply them in linear light
// (blend_tables.hpp). The daemon and procam-render draw from the same result.
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <vector>

#include "blend/blend_tables.hpp"
#include "blend/curved_feather.hpp"
#include "core/error.hpp"
#include "keystone/inscribed_rect.hpp"
#include "render/dome_master.hpp"
#include "render/post_render_warp.hpp"
#include "render/warp_map.hpp"

namespace procam::blend {

struct CurvedDisplayOptions {
  int raster_cells = 192;  // coarse cells along the union's longer side (4x finer after)
  int lookup_step = 8;     // projector pixels between lookup nodes
  CurvedFeatherOptions feather;
};

struct CurvedDisplay {
  Mat34 viewer = Mat34::Zero();  // world -> content pixels: a pinhole at the eye
  Vec3 eye = Vec3::Zero();
  // The eye's turn (render::uprightEyeRotation, world -> eye): with `rect` it places the
  // content for an eye elsewhere (a tracked viewer) as render::contentViewMatrix does.
  Mat3 rotation = Mat3::Identity();
  keystone::AxisRect rect;               // the content on the eye's plane z = 1 (x right, y up)
  double cell = 0;                       // the rectangle's accuracy on that plane
  double union_area = 0;                 // of the images on that plane
  std::vector<render::WarpGrid> lookup;  // per projector: pixel -> content pixel
  // Dome-master content (render/dome_master.hpp) in place of the eye's pinhole: then
  // `viewer`, `rotation`, `rect` and `cell` are unused, and `coverage` is the part of
  // the master's circle the projectors draw.
  std::optional<render::DomeMaster> dome;
  double coverage = 0;
};

struct CurvedBlend : BlendTables {
  CurvedDisplay display;
};

// kInvalidInput for no projectors, a missing surface, bad sizes or a non-finite eye or
// matrix; kDegenerate when no projector's image is on the surface, part of one lies
// behind the eye or the eye looks straight up or down at them; kNotFound when no
// rectangle fits.
Result<CurvedDisplay> solveCurvedDisplay(std::span<const SurfaceProjector> projectors,
                                         const Vec3& eye, cv::Size content,
                                         const CurvedDisplayOptions& options = {});

// The display, its weights and blend tables. `responses` as blendTables takes them.
Result<CurvedBlend> makeCurvedBlend(std::span<const SurfaceProjector> projectors,
                                    std::span<const std::optional<ProjectorResponse>> responses,
                                    const Vec3& eye, cv::Size content,
                                    const CurvedDisplayOptions& options = {});

// The display of dome-master content: every projector's lookup warp onto `master`.
// kInvalidInput for no projectors, a missing surface, bad sizes or lookup step;
// kDegenerate when no projector draws any of the master's circle.
Result<CurvedDisplay> solveDomeDisplay(std::span<const SurfaceProjector> projectors,
                                       const render::DomeMaster& master,
                                       const CurvedDisplayOptions& options = {});

// The dome display, its weights and blend tables. `responses` as blendTables takes them.
Result<CurvedBlend> makeDomeBlend(std::span<const SurfaceProjector> projectors,
                                  std::span<const std::optional<ProjectorResponse>> responses,
                                  const render::DomeMaster& master,
                                  const CurvedDisplayOptions& options = {});

// A projector's post-rendering warp for status and display.json: {"source": "measured"
// or "lens", "rms_px", "max_px" (how far it moves the pinhole's pixels), "points" (the
// measured vertices)}.
nlohmann::json postWarpJson(const render::PostRenderWarp& warp);

}  // namespace procam::blend
